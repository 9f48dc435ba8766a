"""scripts/dft_diagnostics.py reads a reproduction's runs and explains them without running anything."""

from pathlib import Path

import pandas as pd

from tests.helpers import load_script

ROOT = Path(__file__).resolve().parents[1]
RUNS = ROOT / "docs" / "reports" / "billing2015" / "runs.csv"


def test_every_failed_spa_run_of_case_2_is_placed_between_two_named_walls():
    script, runs = load_script("dft_diagnostics"), pd.read_csv(RUNS)
    failures = script.failure_table(runs)
    failed = runs[(runs.case == "case2") & (runs.controller == "dft") & ~runs.reached]
    assert len(failures) == len(failed)
    assert failures.walls.str.fullmatch(r"\S+ / \S+").all()
    assert (failures.gap_cm >= 0).all() and (failures.from_start >= 0).all()


def test_the_clearance_table_has_one_row_per_clearance_and_noise_with_its_interval():
    script = load_script("dft_diagnostics")
    table = script.clearance_table(pd.read_csv(RUNS))
    assert len(table) == len(script.CLEARANCES) * 2
    assert ((table.ci_low <= table["mean"]) & (table["mean"] <= table.ci_high)).all()
