"""Crash-safe saved state: a whole snapshot or a one-line refusal, never a half-written
file resumed from, and a world killed at any moment of its saves ends as the uninterrupted run."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from swarm.core.errors import StateError
from swarm.engines.grid import Engine
from swarm.scenario import load_scenario
from tests.distributed import free_endpoint, saving_world_cmd, start_agents, stop
from world_server import persist


def _saved(path: Path, tick: int, size: int = 64) -> None:
    """A snapshot whose every array holds its tick: a torn one would show."""
    persist.save_arrays(path, {"tick": np.array(tick), "a": np.full(size, tick, np.int64),
                               "b": np.full((size, 3), tick, np.float64)}, {"tick": tick, "stats": {}})  # fmt: skip


def _whole(path: Path) -> int:
    arrays, meta = persist.load_arrays(path)
    tick = meta["tick"]
    assert int(arrays["tick"]) == tick and (arrays["a"] == tick).all() and (arrays["b"] == tick).all()
    return tick


def test_every_cut_or_flipped_byte_is_refused_in_one_line_or_changes_nothing(tmp_path):
    """A byte the content depends on, changed, fails the checksum or the archive; one it does not
    (a zip timestamp) loads the same snapshot."""
    path = tmp_path / "r.state.npz"
    _saved(path, 7, size=4)
    data = path.read_bytes()
    bad = tmp_path / "bad.state.npz"
    for cut in range(0, len(data), 7):
        bad.write_bytes(data[:cut])
        with pytest.raises(StateError, match="delete it to start the run over"):
            persist.load_arrays(bad)
    refused = 0
    for at in range(len(data)):
        bad.write_bytes(data[:at] + bytes([data[at] ^ 0x5A]) + data[at + 1 :])
        try:
            assert _whole(bad) == 7
        except StateError as exc:
            assert str(exc).startswith(f"{bad}: saved state ") and "\n" not in str(exc)
            refused += 1
    assert refused > len(data) // 2


def test_old_foreign_and_other_format_files_are_refused(tmp_path):
    old = tmp_path / "old.state.npz"
    np.savez(old, meta=np.array(json.dumps({"tick": 1})), a=np.zeros(3))  # no checksum: written before them
    with pytest.raises(StateError, match="has no checksum"):
        persist.load_arrays(old)
    other = tmp_path / "other.state.npz"
    text = json.dumps({"tick": 1})
    check = json.dumps({"format": persist.FORMAT + 1, "sha256": persist.digest(text, {})})
    np.savez(other, meta=np.array(text), checksum=np.array(check))
    with pytest.raises(StateError, match=f"format {persist.FORMAT + 1}"):
        persist.load_arrays(other)
    tampered = tmp_path / "tampered.state.npz"
    _saved(tampered, 3)
    with np.load(tampered) as data:
        content = {k: data[k] for k in data.files}
    content["a"] = content["a"] + 1  # a whole archive, the content changed
    np.savez(tampered, **content)
    with pytest.raises(StateError, match="fails its checksum"):
        persist.load_arrays(tampered)


def test_a_leftover_tmp_is_ignored_and_replaced(tmp_path):
    path = tmp_path / "r.state.npz"
    _saved(path, 4)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_bytes(b"half a snapshot")  # a write killed before its rename
    assert _whole(path) == 4
    _saved(path, 5)
    assert _whole(path) == 5 and not tmp.exists()


WRITER = """
import sys
from pathlib import Path
import numpy as np
from world_server import persist
path, tick = Path(sys.argv[1]), int(sys.argv[2])
while True:
    tick += 1
    persist.save_arrays(path, {"tick": np.array(tick), "a": np.full(1 << 19, tick, np.int64),
                               "b": np.full((1 << 17, 3), tick, np.float64)}, {"tick": tick, "stats": {}})
"""


def test_kill_9_during_saves_leaves_the_last_whole_snapshot(tmp_path):
    """A process that does nothing but save 7 MB snapshots, killed at seeded random moments:
    each time the file is the last whole snapshot and the next process goes on from it."""
    path = tmp_path / "w.state.npz"
    rng = np.random.default_rng(11)
    tick = last = 0
    for _ in range(6):
        writer = subprocess.Popen([sys.executable, "-c", WRITER, str(path), str(tick)])
        try:
            deadline = time.monotonic() + 60
            while not (path.exists() and _whole(path) > tick):  # it has saved at least once
                assert time.monotonic() < deadline and writer.poll() is None, "the writer never saved"
                time.sleep(0.01)
            time.sleep(rng.uniform(0.0, 0.3))
        finally:
            os.kill(writer.pid, signal.SIGKILL)
            writer.wait()
        tick = _whole(path)
        assert tick > last
        last = tick


def test_a_damaged_or_incomplete_state_stops_swarm_world_in_one_line(tmp_path):
    state = persist.state_path(tmp_path, "cut")
    _saved(state, 9)
    state.write_bytes(state.read_bytes()[:-100])
    persist.save_arrays(persist.state_path(tmp_path, "keyless"), {"tick": np.array(1)}, {"stats": {}})
    for run_id, problem in (("cut", "cut short or damaged"), ("keyless", "lacks 'scenario'")):
        out = subprocess.run([sys.executable, "-m", "swarm", "world", "setup1", "--run-id", run_id, "--state-dir",
                              str(tmp_path), "--listen", free_endpoint(), "--start-timeout", "1"],
                             capture_output=True, text=True, timeout=120)  # fmt: skip
        lines = out.stderr.strip().splitlines()
        assert out.returncode == 2 and len(lines) == 1 and "Traceback" not in out.stderr, out.stderr
        assert str(persist.state_path(tmp_path, run_id)) in lines[0] and problem in lines[0], lines[0]
        assert "delete it to start the run over, or point --state-dir elsewhere" in lines[0]


@pytest.mark.experiment  # four world starts: 43 s on a quiet 2-core machine, minutes under load
def test_kill_9_at_random_moments_of_a_world_saving_every_tick_ends_as_swarm_run(tmp_path):
    """The world saves after every tick; kill -9 at seeded random moments (mid-save or not),
    restart it each time: every restart resumes from a whole snapshot at or after the last one,
    and the run ends with the in-process run's result."""
    scenario = load_scenario("setup1").with_overrides(agents=3, seed=4)
    expected = Engine(scenario).run().summary
    endpoint = free_endpoint()
    state = persist.state_path(tmp_path, "kills")
    summary_file = tmp_path / "summary.json"
    world_cmd = saving_world_cmd(tmp_path, "kills", endpoint, 1)
    rng = np.random.default_rng(5)
    procs = start_agents(endpoint, "kills", "cmarking", 3)
    try:
        last = 0
        for _ in range(3):
            world = subprocess.Popen(world_cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
            procs.append(world)
            deadline = time.monotonic() + 120
            while not (state.exists() and persist.load(state)["tick"] > last):  # ticking again
                assert time.monotonic() < deadline and world.poll() is None, "the world never saved"
                time.sleep(0.005)
            time.sleep(rng.uniform(0.0, 0.4))
            os.kill(world.pid, signal.SIGKILL)
            world.wait()
            tick = persist.load(state)["tick"]
            assert tick > last
            last = tick
        world = subprocess.Popen(world_cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        procs.append(world)
        assert world.wait(timeout=300) == 0, world.stderr.read().decode()[-3000:]
        summary = json.loads(summary_file.read_text())
        for key in ("iterations", "delivered", "total", "finished", "explored_cells", "optimal_cells"):
            assert summary[key] == expected[key], (key, last)
        assert summary["missed_ticks"] == 0 and summary["rejected_messages"] == 0
    finally:
        stop(procs)


def test_a_sweep_row_cut_inside_its_last_number_is_run_again(tmp_path):
    from swarm.sweeps.outputs import RunsFile

    path = tmp_path / "runs.csv"
    runs = RunsFile(path, ["scenario", "seed"], ["delivered", "wall_s"], fresh=True)
    runs.write([{"scenario": "setup1", "seed": 1, "delivered": 60, "wall_s": 1.25}])
    with open(path, "a") as f:
        f.write("setup1,2,60,1.2")  # killed while appending: the rest of 1.25 and the newline never came
    again = RunsFile(path, ["scenario", "seed"], ["delivered", "wall_s"], fresh=False)
    assert list(again.rows) == [("setup1", "1")]


def test_a_recording_world_killed_mid_run_leaves_a_readable_file(tmp_path):
    """kill -9 a recording world past tick 600: the file reads back (run meta, map, ticks) up to the
    last batch the recorder handed rerun, so at most 256 ticks are lost."""
    from swarm.review.report import RecordingError, read_recording

    endpoint = free_endpoint()
    state = persist.state_path(tmp_path, "rec")
    rrd = tmp_path / "rec.rrd"
    world = subprocess.Popen([sys.executable, "-m", "swarm", "world", "maze", "--agents", "4", "--seed", "3",
                              "--run-id", "rec", "--listen", endpoint, "--state-dir", str(tmp_path),
                              "--persist-every", "100", "--record", str(rrd)],
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)  # fmt: skip
    procs = [world, *start_agents(endpoint, "rec", "cmarking", 2, count=2)]
    try:
        deadline = time.monotonic() + 120
        while not (state.exists() and persist.load(state)["tick"] >= 600):
            assert time.monotonic() < deadline and world.poll() is None, "the world never reached tick 600"
            time.sleep(0.01)
        os.kill(world.pid, signal.SIGKILL)
        world.wait()
        saved = persist.load(state)["tick"]
        with pytest.raises(RecordingError, match=r"truncated: it holds ticks 0\.\.(\d+)") as cut:
            read_recording(rrd)
        last = int(str(cut.value).split("ticks 0..")[1].split(" ")[0])
        assert (last + 1) % 256 == 0 and last >= saved - 256, (last, saved)
    finally:
        stop(procs)
