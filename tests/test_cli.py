"""The `swarm` command, run as a real process."""

import csv
import json
import subprocess
import sys

import pytest

SWARM = [sys.executable, "-m", "swarm"]
KEYS = {"iterations", "delivered", "total", "finished", "apf_optimal", "explored_cells", "reachable_cells",
        "seed", "agents", "controller"}  # fmt: skip


def swarm(*args, check=True):
    return subprocess.run([*SWARM, *args], capture_output=True, text=True, check=check, timeout=600)


def test_help_lists_the_commands():
    out = swarm("--help").stdout
    for word in ("run", "experiment", "bench", "examples"):
        assert word in out
    assert "--until" in swarm("run", "--help").stdout


def test_run_json_has_the_summary_keys_and_matches_the_engine():
    from swarm.engines.grid import Engine
    from swarm.scenario import load_scenario

    out = json.loads(swarm("run", "setup2", "--agents", "3", "--seed", "12", "--json").stdout)
    assert set(out) >= KEYS
    assert out["finished"] and out["delivered"] == out["total"] == 2000 and out["agents"] == 3 and out["seed"] == 12
    expected = Engine(load_scenario("setup2").with_overrides(agents=3, seed=12)).run().summary
    assert out["iterations"] == expected["iterations"]


def test_run_until_converged_reports_an_optimal_apf():
    out = json.loads(swarm("run", "maze", "--controller", "marking", "--until", "converged", "--json").stdout)
    assert out["finished"] and out["apf_optimal"] and out["explored_cells"] == out["reachable_cells"]


def test_unfinished_run_exits_1():
    result = swarm("run", "setup1", "--max-iterations", "10", "--json", check=False)
    assert result.returncode == 1 and json.loads(result.stdout)["finished"] is False


@pytest.mark.parametrize(
    ("args", "message"),
    [(["run", "nowhere.toml"], "no such file or preset"),
     (["run", "setup1", "--controller", "ant", "--until", "converged"], "ants build no marks"),
     (["run", "setup4"], "no such file or preset")],
)  # fmt: skip
def test_errors_are_clear_and_exit_2(args, message):
    result = swarm(*args, check=False)
    assert result.returncode == 2 and message in result.stderr and "Traceback" not in result.stderr


def test_bad_arguments_exit_2():
    result = swarm("run", "setup1", "--agents", "0", check=False)
    assert result.returncode == 2 and "positive integer" in result.stderr


def test_broken_scenario_file_names_the_file(tmp_path):
    bad = tmp_path / "broken.toml"
    bad.write_text('[map]\nascii = """\n###\n#B#\n##\n"""\n')
    result = swarm("run", str(bad), check=False)
    assert result.returncode == 2 and "broken.toml: map row 3" in result.stderr


def test_experiment_writes_every_artefact(tmp_path):
    result = swarm("experiment", "table2", "--reps", "3", "--jobs", "2", "--out", str(tmp_path))
    assert "paper: mean" in result.stdout
    for name in ("runs.csv", "summary.csv", "table.md", "plot.png"):
        assert (tmp_path / name).stat().st_size > 0
    with open(tmp_path / "runs.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 24 and set(rows[0]) >= {"agents", "size", "seed", "controller", "iterations", "finished"}
    assert all(r["finished"] == "True" for r in rows)
    assert "1,790.4" in (tmp_path / "table.md").read_text()
