"""Why the DFT reproduction's numbers are what they are, read from its report's runs (no new runs).

Two analyses behind docs/dft.md's "Why the results are what they are", both on the report's
confirmation seeds:

- case 1: SPA's path length against A* paths that keep 4, 6 and 8 cm from the walls (SPA keeps
  to the middle of the corridors; L_o keeps the paper's 4 cm);
- case 2: where each SPA run that missed its goal ended: how far from its start, and the two
  nearest walls with the gap between them (a 7.4 cm robot in a 10-11 cm passage);
- case 3: the paper's three claims with the runs the report leaves out (the box appeared on the
  robot) kept, beside the report's numbers: what the drop rule changes.

    python scripts/dft_diagnostics.py                                  # docs/reports/billing2015/runs.csv
    python scripts/dft_diagnostics.py --runs OUT/runs.csv              # another `swarm reproduce billing2015`
                                                                       # (its case3.csv read beside it)
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from agents.controllers.navigation.astar import Planner
from swarm.experiments.billing2015.reproduce import case3_tally, case3_tests
from swarm.experiments.protocol import p_text
from swarm.experiments.report import markdown_table
from swarm.scenario import load_scenario
from world_server.arena.scenario import clearance_at

CLEARANCES = (0.04, 0.06, 0.08)  # metres; L_o's is the first
NO_SEGMENTS = np.zeros((0, 4))
NEAR_START = 0.15  # metres: a failed run that ended this close to its start barely left it


def spa_runs(runs: pd.DataFrame, case: str) -> pd.DataFrame:
    return runs[(runs.case == case) & (runs.controller == "dft")]


def clearance_table(runs: pd.DataFrame) -> pd.DataFrame:
    """L_p / L_o of case 1's reached SPA runs, L_o planned with each clearance (bootstrap BCa 95%)."""
    scenario = load_scenario("zmaze")
    rows = []
    for clearance in CLEARANCES:
        planner = Planner(scenario.size, scenario.wall_rects(), scenario.wall_segments(), 0.01, clearance)
        for noise, group in spa_runs(runs, "case1")[lambda d: d.reached].groupby("noise"):
            ratios = []
            for run in group.itertuples():
                optimum = planner.plan((run.start_x, run.start_y), (run.goal_x, run.goal_y))[0]
                if math.isfinite(optimum) and optimum > 0:
                    ratios.append(run.path_length / optimum)
            ratio = np.array(ratios)
            ci = stats.bootstrap((ratio,), np.mean, method="BCa", random_state=0).confidence_interval
            rows.append({"clearance_cm": round(clearance * 100), "noise": noise, "n": len(ratio),
                         "mean": ratio.mean(), "ci_low": ci.low, "ci_high": ci.high})  # fmt: skip
    return pd.DataFrame(rows).round(3)


def nearest_gap(point: np.ndarray, names: list[str], rects: np.ndarray) -> tuple[str, str, float]:
    """The two rectangular walls nearest the point and the free gap between them (metres)."""
    each = [clearance_at(point[None], rect[None], NO_SEGMENTS)[0] for rect in rects]
    first, second = np.argsort(each)[:2]
    a, b = rects[first], rects[second]  # x0, y0, x1, y1
    dx = max(a[0] - b[2], b[0] - a[2], 0.0)
    dy = max(a[1] - b[3], b[1] - a[3], 0.0)
    return names[first], names[second], math.hypot(dx, dy)


def failure_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Case 2's SPA runs that missed their goal: where each ended, and what is around it."""
    maze = load_scenario("large-maze")
    names, rects = [w.name for w in maze.walls if w.shape == "rect"], maze.wall_rects()
    failed = spa_runs(runs, "case2")[lambda d: ~d.reached].copy()
    failed["from_start"] = np.hypot(failed.final_x - failed.start_x, failed.final_y - failed.start_y)
    failed["to_goal"] = np.hypot(failed.final_x - failed.goal_x, failed.final_y - failed.goal_y)
    around = [nearest_gap(np.array([x, y]), names, rects) for x, y in zip(failed.final_x, failed.final_y, strict=True)]
    failed["walls"] = [" / ".join(sorted((a, b))) for a, b, _ in around]
    failed["gap_cm"] = [100 * gap for _, _, gap in around]
    columns = ["noise", "pair", "final_x", "final_y", "from_start", "to_goal", "path_length", "walls", "gap_cm"]
    return failed[columns].sort_values(["walls", "pair", "noise"]).round(2)


def case3_drop_table(case3: pd.DataFrame) -> pd.DataFrame:
    """Case 3's claims, judged as the report judges them, on the kept runs and on every run: the early
    obstacle's share south and the late one's share north (exact binomial against one half), and the red
    switches of full against partial boxes between the two (Fisher's exact test)."""
    rows = []
    for which, sel in (("box on the robot left out (the report)", case3[~case3.on_robot]), ("none left out", case3)):
        t = case3_tally(sel.to_dict("records"))
        red, mid = t["red"], t["mid"]
        early, late, switches = case3_tests(t)
        rows.append({"runs": which, "n": len(sel),
                     "early: south": f"{t['south']}/{t['early']}", "p": p_text(early.p),
                     "late: north": f"{t['north']}/{t['late']}", "p ": p_text(late.p),
                     "mid, red: full": f"{red['full']}/{mid['full']}", "partial": f"{red['partial']}/{mid['partial']}",
                     "Fisher p": p_text(switches.p)})  # fmt: skip
    return pd.DataFrame(rows)


def markdown(frame: pd.DataFrame) -> str:
    return markdown_table(list(frame.columns), [[f"{v:g}" if isinstance(v, float) else str(v) for v in row]
                                                for row in frame.itertuples(index=False)])  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=Path, default=Path("docs/reports/billing2015/runs.csv"),
                        help="runs.csv of `swarm reproduce billing2015` (default: the bundled report's)")  # fmt: skip
    path = parser.parse_args().runs
    runs = pd.read_csv(path)
    print("Case 1, SPA's reached runs: L_p / L_o with L_o planned at each clearance\n")
    print(markdown(clearance_table(runs)))
    failures = failure_table(runs)
    near = failures.from_start < NEAR_START
    print(f"\nCase 2, SPA's runs that missed their goal: {len(failures)} "
          f"({near.sum()} ended within {NEAR_START * 100:.0f} cm of their start)\n")  # fmt: skip
    print(markdown(failures))
    case3 = pd.read_csv(path.with_name("case3.csv"))
    print("\nCase 3: the paper's claims with and without the runs whose box appeared on the robot\n")
    print(markdown(case3_drop_table(case3)))


if __name__ == "__main__":
    main()
