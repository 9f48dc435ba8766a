"""`swarm experiment dft-sensitivity`: case 2's SPA runs with one declared parameter at another level."""

from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

import pytest

from swarm.experiments.billing2015.dft import run_dft_experiment
from swarm.experiments.billing2015.sensitivity import BY_NAME, SWEPT, declared_value, level_set, run_sensitivity

ROOT = Path(__file__).resolve().parents[1]
TICKS = 60


def _rows(path: Path) -> list[dict]:
    with open(path) as f:
        return list(csv.DictReader(f))


def test_every_swept_parameter_is_declared_and_its_levels_hold_the_declared_one():
    for s in SWEPT:
        assert declared_value(s) in s.levels and len(set(s.levels)) == len(s.levels), s.name


@pytest.mark.parametrize("name", list(BY_NAME))
def test_a_level_reaches_the_controller_for_one_run_and_is_undone(name):
    from agents.controllers.dft import controller, params

    s = BY_NAME[name]
    other = next(v for v in s.levels if v != declared_value(s))

    def seen() -> float:
        if s.cls == "MapNoise":
            return controller.MAP_NOISE[s.field]
        return getattr(getattr(controller, s.cls)(), s.field)

    with level_set(name, other):
        assert seen() == other
    assert seen() == declared_value(s)
    with level_set(name, declared_value(s)):  # the declared level changes nothing
        assert controller.SpaParams is params.SpaParams and controller.Interface is params.Interface
        assert seen() == declared_value(s)


@pytest.mark.timeout(120)
def test_the_sweep_writes_its_files_and_its_declared_rows_are_dft_case2s(tmp_path):
    out = tmp_path / "sens"
    result = run_sensitivity("dft-sensitivity", None, reps=1, jobs=1, seed=3, out=out, parameter="map_noise",
                             max_ticks=TICKS, progress=False)  # fmt: skip
    for f in ("runs.csv", "summary.csv", "table.md", "plot.png"):
        assert (out / f).stat().st_size > 0, f
    assert "| map_noise | 0.05 (declared) | " in result["markdown"]
    rows = _rows(out / "runs.csv")
    assert [(r["parameter"], float(r["level"])) for r in rows] == [("map_noise", v) for v in (0.05, 0.005, 1.0)]
    assert len({r["pair"] for r in rows}) == 1 and len({(r["start_x"], r["goal_x"]) for r in rows}) == 1

    run_dft_experiment("dft-case2", None, 1, 1, 3, tmp_path / "case2", noise="low", max_ticks=TICKS, progress=False)
    (plain,) = [r for r in _rows(tmp_path / "case2" / "runs.csv") if r["controller"] == "dft"]
    declared = next(r for r in rows if r["declared_level"] == "True")
    same = [k for k in plain if k != "wall_seconds"]
    assert {k: declared[k] for k in same} == {k: plain[k] for k in same}
    # the other levels are the same pair and seed, run with another map noise
    assert all(r[k] == plain[k] for r in rows for k in ("pair", "start_x", "start_y", "goal_x", "goal_y"))
    assert any((r["final_x"], r["final_y"]) != (plain["final_x"], plain["final_y"]) for r in rows)


def test_an_unknown_parameter_is_refused_in_one_line(tmp_path):
    done = subprocess.run([sys.executable, "-m", "swarm", "experiment", "dft-sensitivity", "--parameter", "tau",
                           "--reps", "1", "--out", str(tmp_path / "out")], capture_output=True, text=True, cwd=ROOT,
                          timeout=60)  # fmt: skip
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1, done.stderr
    assert lines[0].startswith("swarm: error: ") and "'tau' is not swept" in lines[0] and "prox_gain" in lines[0]
    assert not (tmp_path / "out").exists()


def test_its_seeds_lie_in_one_range_development_or_confirmation(tmp_path):
    """Seed 9998 draws the pairs, which run on 9999 and 10000: the last is a confirmation seed."""
    from swarm.core.errors import ScenarioError

    with pytest.raises(ScenarioError, match="within one range: development"):
        run_sensitivity("dft-sensitivity", None, reps=2, jobs=1, seed=9998, out=tmp_path / "out", progress=False)
    assert not (tmp_path / "out").exists()
