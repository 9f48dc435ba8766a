"""`swarm bench recording`: one real in-process row, and the table's arithmetic."""

from __future__ import annotations

from swarm.bench.recording.measure import _in_process, _warm_up, format_recording_bench


def test_an_in_process_row_times_the_recorded_run_in_parts_that_add_up(tmp_path):
    _warm_up(tmp_path)  # as the bench does: on a cold cache the plain run would include compiling
    row = _in_process(20, range(1, 2), tmp_path)
    parts = row["open_ms_per_run"] + row["recorded_run_ms_per_run"] + row["close_ms_per_run"]
    recorded_ms = row["ticks"] / row["recorded_ticks_per_second"] * 1000
    assert abs(parts - recorded_ms) <= 0.02 * recorded_ms + 0.3  # rounding of ticks/s and of each part
    assert row["ticks"] > 0 and row["bytes_per_tick"] > 0 and (tmp_path / "inproc-20-1.rrd").exists()
    assert 0 <= row["cost"] < 1


def test_the_table_gives_the_20_percent_budget_as_a_quarter_of_the_plain_run():
    row = {"runtime": "in-process", "agents": 160, "ticks_per_second": 30000, "recorded_ticks_per_second": 24000,
           "cost": 0.2, "bytes_per_tick": 1300, "mb_per_run": 0.5, "plain_ms_per_run": 12.0,
           "open_ms_per_run": 1.0, "recorded_run_ms_per_run": 13.0, "close_ms_per_run": 1.0,
           "drained_close_ms_per_run": 0.9}  # fmt: skip
    text = format_recording_bench({"runs": [row]})
    assert "    160    12.0     1.0    13.0     1.0         3.0             0.9" in text
    assert "20%" in text


def test_a_robots_record_message_carries_its_image_every_tenth_tick():
    from swarm.bench.recording.measure import record_bytes

    scalar, image = record_bytes(0), record_bytes(128)
    assert 0 < scalar < 100
    assert 128 * 128 * 8 / 10 < image - scalar < 128 * 128 * 8 / 10 + 200  # float64 on the wire, every 10 ticks
