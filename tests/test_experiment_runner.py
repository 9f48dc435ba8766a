"""The one experiment runner: jobs over a real spawned process pool, rows in the jobs' order, the files
every experiment writes.  Retries, failures and Ray: test_executors.py."""

from __future__ import annotations

import csv
import os
import time

from swarm.experiments.runner import Outputs, batch_run, cross, processes_for, write_csv

_WARMED: list[int] = []


def _warm(value: int) -> None:
    _WARMED.append(value)


def _slow_first(job: tuple[int, float]) -> dict:
    """Early jobs sleep longest, so a pool finishes them last."""
    k, delay = job
    time.sleep(delay)
    return {"job": k, "pid": os.getpid(), "warmed": list(_WARMED)}


def test_rows_come_back_in_the_jobs_order_whichever_worker_finishes_first():
    work = [(k, delay) for k, delay in enumerate((0.4, 0.3, 0.1, 0.0))]
    rows = batch_run(_slow_first, work, jobs=2, progress=False)
    assert [r["job"] for r in rows] == [0, 1, 2, 3]
    assert len({r["pid"] for r in rows}) == 2 and os.getpid() not in {r["pid"] for r in rows}


def test_warm_up_runs_here_and_in_every_worker_before_any_job():
    _WARMED.clear()
    rows = batch_run(_slow_first, [(k, 0.0) for k in range(3)], jobs=2, progress=False, warm_up=_warm, warm_args=(7,))
    assert _WARMED == [7]
    assert all(r["warmed"] == [7] for r in rows)


def test_one_process_runs_here_without_a_pool():
    rows = batch_run(_slow_first, [(0, 0.0), (1, 0.0)], jobs=1, progress=False)
    assert {r["pid"] for r in rows} == {os.getpid()}


def test_processes_never_outnumber_the_work():
    assert processes_for(8, 3) == 3 and processes_for(None, 1) == 1 and processes_for(2, 10) == 2


def test_cross_is_conditions_times_replicates_conditions_outermost():
    assert cross(["a", "b"], range(2)) == [("a", 0), ("a", 1), ("b", 0), ("b", 1)]
    assert cross(["a", "b"], iter([5])) == [("a", 5), ("b", 5)]  # a one-shot iterable serves every condition


def test_outputs_write_runs_first_then_summary_and_table(tmp_path):
    out = Outputs(tmp_path / "exp", "exp")
    rows = [{"a": 1, "b": 2}, {"a": 3, "b": 4, "c": 5}]
    out.runs(rows, ["a", "b"])
    assert (tmp_path / "exp" / "runs.csv").is_file() and not (tmp_path / "exp" / "summary.csv").exists()
    result = out.finish([{"x": 1}], "# table\n")
    assert result == {"name": "exp", "out": str(tmp_path / "exp"), "runs": 2, "summary": [{"x": 1}],
                      "markdown": "# table\n"}  # fmt: skip
    with open(tmp_path / "exp" / "runs.csv") as f:
        assert list(csv.DictReader(f)) == [{"a": "1", "b": "2"}, {"a": "3", "b": "4"}]
    assert (tmp_path / "exp" / "table.md").read_text() == "# table\n"
    out.finish(None, "# again\n")  # no summary rows: summary.csv is left as it is
    assert (tmp_path / "exp" / "summary.csv").read_text().splitlines() == ["x", "1"]


def test_write_csv_takes_every_key_in_first_seen_order(tmp_path):
    write_csv(tmp_path / "r.csv", [{"b": 1}, {"a": 2, "b": 3}])
    assert (tmp_path / "r.csv").read_text().splitlines() == ["b,a", "1,", "3,2"]
