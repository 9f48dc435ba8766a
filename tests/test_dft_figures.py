"""`swarm experiment dft-figures`: the paper's figures drawn from short real runs of the dft controller."""

from __future__ import annotations

import csv
import math

import pytest

from swarm.core.errors import ScenarioError
from swarm.experiments.billing2015.figures import run_dft_figures

FIGURES = ("motivation.png", "activity.png", "planning.png", "velocity.png", "paths.png")


@pytest.mark.timeout(120)
def test_the_figures_are_drawn_and_the_planning_times_are_finite_one_row_per_run(tmp_path):
    result = run_dft_figures("dft-figures", reps=3, jobs=1, seed=0, out=tmp_path, max_ticks=120, progress=False)
    for name in FIGURES:
        png = tmp_path / name
        assert png.is_file() and png.stat().st_size > 1000, name
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
    with open(tmp_path / "planning.csv") as f:
        rows = list(csv.DictReader(f))
    assert [int(r["pair"]) for r in rows] == [1, 2, 3]  # one row per planning run, the Z-maze's first pairs
    for r in rows:
        ticks, length = float(r["planning_ticks"]), float(r["optimal_length"])
        assert math.isfinite(ticks) and 0 < ticks < 1500 and math.isfinite(length) and length >= 0
        assert int(r["seed"]) == int(r["pair"])  # development seeds: seed + pair
    # the farther pairs plan longer (pair 2 starts on its goal)
    by = {int(r["pair"]): r for r in rows}
    assert int(by[2]["planning_ticks"]) < int(by[1]["planning_ticks"])
    md = result["markdown"]
    assert "Spearman rho" in md and "Development seeds" in md and "ticks per metre" in md
    with open(tmp_path / "summary.csv") as f:
        summary = list(csv.DictReader(f))
    assert summary[0]["figure"] == "planning" and summary[0]["planned"] == "3"


def test_the_figures_refuse_seeds_across_both_ranges_and_other_floors(tmp_path):
    with pytest.raises(ScenarioError, match="must lie in one range") as e:
        run_dft_figures("dft-figures", reps=20, jobs=1, seed=9_990, out=tmp_path, progress=False)
    assert "9990 to 10010" in str(e.value) and "\n" not in str(e.value)
    with pytest.raises(ScenarioError, match="--scenario"):
        run_dft_figures("dft-figures", reps=1, jobs=1, seed=0, out=tmp_path, scenario="zmaze", progress=False)
