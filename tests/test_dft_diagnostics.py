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


def test_case_3_is_judged_with_and_without_the_runs_whose_box_appeared_on_the_robot():
    script = load_script("dft_diagnostics")
    runs = pd.DataFrame({"appear": [100, 150, 300, 300, 300, 600], "obstacle": ["full", "full", "full", "partial",
                                                                             "partial", "full"],
                         "route": ["south", "north", "north-then-south", "north-then-south", "north", "north"],
                         "on_robot": [False, True, False, True, False, False]})  # fmt: skip
    kept, every = script.case3_drop_table(runs).to_dict("records")
    assert (kept["n"], kept["early: south"], kept["late: north"]) == (4, "1/1", "1/1")
    assert (kept["mid, red: full"], kept["partial"]) == ("1/1", "0/1")
    assert (every["n"], every["early: south"], every["mid, red: full"], every["partial"]) == (6, "1/2", "1/1", "1/2")
    report = script.case3_drop_table(pd.read_csv(RUNS.with_name("case3.csv")))
    assert report["n"].tolist() == [188, 240]  # the report's kept runs, and all 240
