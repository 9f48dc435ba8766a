"""`swarm experiment bg-ablations`: what each of our choices, and two of the paper's numbers, do to
experiments 1 and 3.2.

Each condition changes one thing of the declared animat (agents/controllers/bg/params.py):

- eq. 10's trans-subthalamic cross term off (`[bg.gpr] cross = 0`);
- the cortical feedback of eqs. 15-20 as printed, not counted from rest (`[bg] feedback = "literal"`);
- the wheels held during a dorsal act, a rule stopping the animat beside the loops (`[bg] hold_wheels = true`);
- the dopamine level lambda at 0.1 and 0.3 (the paper's 0.2; `[bg.gpr] dopamine`);
- biased odometry and compass: the paper's +-5% odometric error and half its +-10 degree compass error
  drawn once per animat and run instead of every tick, so that the odometric position drifts.

Experiment 1 runs condition A (taxon + map) only: every change concerns the loops or the map, and A is
where both act.  Experiment 3.2 runs every ratio on maps made by the declared animat (so a change to the
loops is measured in the test, where the choice is made), except biased odometry and compass, whose
maps are made with the bias too: drift acts while the map is made, and map and test are one animat
(the same seed, so the same bias; with `--maps` fewer than `--reps`, test k loads map k mod maps, drawn
with another seed's bias).  Test k of every condition runs on map k with seed + k: the
conditions are paired with the declared animat test by test (McNemar), and survival is compared by
log-rank with runs alive at 4 h censored.  Beside survival, the table counts the control periods spent in
an act (ReloadE, ReloadEp) and the share of them in which the animat moved (bg.MOVING): with the wheels
left to the loops, eq. 10 is what stops it.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from swarm.core.errors import ScenarioError
from swarm.core.plots import pyplot, save_figure
from swarm.experiments import report as R
from swarm.experiments import stats as S
from swarm.experiments.girard2005 import bg
from swarm.experiments.girard2005.paper import PAPER_SURVIVAL, PAPER_TMAZE, TMAZE_TESTS
from swarm.experiments.runner import Outputs, batch_run

MODEL = "declared animat"
DEG = math.pi / 180.0
# condition -> ([bg] changes, sensor changes)
ABLATIONS: dict[str, tuple[dict[str, Any], dict[str, dict[str, float]]]] = {
    MODEL: ({}, {}),
    "no cross term (eq. 10)": ({"gpr": {"cross": 0.0}}, {}),
    "literal cortical feedback": ({"feedback": "literal"}, {}),
    "wheels held": ({"hold_wheels": True}, {}),
    "dopamine 0.1": ({"gpr": {"dopamine": 0.1}}, {}),
    "dopamine 0.3": ({"gpr": {"dopamine": 0.3}}, {}),
    "biased odometry and compass": ({}, {"odometry": {"bias": 0.05}, "compass": {"bias": 5 * DEG}}),
}
REPS = 10  # survival runs and T-maze tests per condition (and ratio)
CAP = 4 * 3600.0


def jobs_for(reps: int, seed: int, maps: dict[str, dict[str, list[dict]]], cap: int | None,
             floor: str | None = None) -> tuple[list[tuple], list[tuple]]:  # fmt: skip
    """(survival jobs, T-maze test jobs), each (condition, the experiment's job): run k of every condition with
    seed + k, test k on map k mod the maps of its condition (`maps[condition]`, by map set); survival on `floor`
    (default experiment 1's)."""
    floor = floor or bg.SCENARIO["bg-survival"]
    survival = [(label, ("A", k, seed + k, changes, cap, floor, sensors))
                for label, (changes, sensors) in ABLATIONS.items() for k in range(reps)]  # fmt: skip
    tests = [(label, (*job, sensors)) for label, (changes, sensors) in ABLATIONS.items()
             for job in bg.test_jobs("bg-tmaze", reps, seed, maps[label], changes)]  # fmt: skip
    return survival, tests


def maps_for(count: int, seed: int, floors: tuple[str, ...], jobs: int | None, progress: bool,
             seconds: float) -> dict[str, dict[str, list[dict]]]:  # fmt: skip
    """Each condition's T-maze maps: the declared animat's, or for a condition that changes the sensors, maps
    made with that change (one set per distinct change)."""
    keys = {label: repr(sorted(sensors.items())) for label, (_, sensors) in ABLATIONS.items()}
    made: dict[str, dict[str, list[dict]]] = {}
    for label, (_, sensors) in ABLATIONS.items():
        if keys[label] not in made:
            made[keys[label]] = bg.make_maps("bg-tmaze", count, seed, floors, jobs, progress, seconds=seconds,
                                             sensors=sensors or None)  # fmt: skip
    return {label: made[key] for label, key in keys.items()}


def run_survival(job: tuple) -> dict:
    """bg.run_survival, the condition's name carried into the row."""
    label, survival = job
    return {**bg.run_survival(survival), "ablation": label}


def run_test(job: tuple) -> dict:
    """bg.run_test, the condition's name carried into the row."""
    label, test = job
    return {**bg.run_test(test), "ablation": label}


def run_ablations(experiment: str, reps: int | None, jobs: int | None, seed: int, out: Path | None,
                  progress: bool = True, max_ticks: int | None = None, ratios: tuple[float, ...] | None = None,
                  maps: int | None = None, mapping_seconds: float = bg.MAPPING_SECONDS,
                  scenario: str | None = None) -> dict:  # fmt: skip
    """Every condition on experiment 1 (A) and 3.2; `maps` mapping runs per T-maze (default one per test), each
    at most `mapping_seconds`; `max_ticks` a shorter cap on survival runs (a smoke run).  `scenario`: one floor
    for both, a T-maze with what bg-tmaze needs (bg.FLOOR_NEEDS), in place of bg-exp1 and the tmaze-R floors."""
    if scenario is not None and ratios is not None:
        raise ScenarioError("command line", "--ratios", "--ratios chooses the tmaze-R floors; --scenario gives one "
                            "floor for both experiments: give one or the other")  # fmt: skip
    reps, maps = bg.reps_and_maps(REPS if reps is None else reps, maps)
    floors = bg.check_floors("bg-ablations" if scenario else "bg-tmaze", scenario, ratios, {})
    out_ = Outputs(out, experiment)
    made = maps_for(maps, seed, floors, jobs, progress, mapping_seconds)
    survival, tests = jobs_for(reps, seed, made, max_ticks, scenario)
    rows = batch_run(run_survival, survival, jobs=jobs, desc=f"{experiment} survival", progress=progress)
    rows += batch_run(run_test, tests, jobs=jobs, desc=f"{experiment} T-maze", progress=progress)
    fields = ["ablation", "experiment", "condition", "run", "seed", "map", "survival_seconds", "died", "branch",
              "chose", "seconds", "distance", "idle_acts", "act_ticks", "act_ticks_moving", "wall_seconds"]  # fmt: skip
    out_.runs([{k: r.get(k, "") for k in fields} for r in rows], fields)
    cap = CAP if max_ticks is None else max_ticks * 0.25
    summary, text = _tables(rows, cap, paper=scenario is None)
    where = "" if scenario is None else (f"  Both on the user's floor {scenario} (--scenario), not the paper's: "
                                         "the paper's numbers are not shown.")  # fmt: skip
    head = (f"# Ablations of the bg animat (experiments 1 and 3.2)\n\n{reps} runs per condition (experiment 1, "
            f"condition A, at most {cap / 3600:.3g} h) and {reps} tests per condition and ratio (experiment 3.2, "
            f"test k on map k of the declared animat, or of an animat with the condition's sensors); seed {seed}.  "
            "Each condition changes one thing of the declared animat (swarm/experiments/girard2005/ablations.py "
            f"says what).{where}\n\n")  # fmt: skip
    result = out_.finish(summary, head + text)
    _plot(rows, out_ / "plot.png")
    return result


def _tables(rows: list[dict], cap: float, paper: bool = True) -> tuple[list[dict], str]:
    live = {a: [r for r in rows if r.get("ablation") == a and "survival_seconds" in r] for a in ABLATIONS}
    t = {a: np.array([r["survival_seconds"] for r in sel], float) for a, sel in live.items()}
    died = {a: np.array([bool(r["died"]) for r in sel]) for a, sel in live.items()}
    ratios = sorted({r["condition"] for r in rows if r.get("experiment") == "bg-tmaze"}, key=str)
    summary, lines = [], []
    for a in ABLATIONS:
        row: dict[str, Any] = {"ablation": a, "runs": len(t[a])}
        km = S.kaplan_meier_median(t[a], died[a])
        row |= {"km_median_s": km.value, "alive_at_cap": int((~died[a]).sum()),
                "restricted_mean_s": S.restricted_mean(t[a], died[a], cap)}  # fmt: skip
        vs = S.logrank(t[a], died[a], t[MODEL], died[MODEL]) if a != MODEL else None
        cells = [a, str(len(t[a])), km.text(5), f"{row['alive_at_cap']}/{len(t[a])}",
                 S.number(row["restricted_mean_s"], 5), "–" if vs is None else S.number(vs.p, 2)]  # fmt: skip
        row["logrank_p"] = None if vs is None else vs.p
        acts = np.array([r.get("act_ticks") or 0 for r in live[a]], float)
        moving = np.array([r.get("act_ticks_moving") or 0 for r in live[a]], float)
        share = S.mean_ci(np.divide(moving, acts, out=np.full(len(acts), np.nan), where=acts > 0))
        row |= {"act_periods": int(acts.sum()), "act_periods_moving": int(moving.sum()),
                "moving_share": share.value}  # fmt: skip
        cells.append(f"{int(acts.sum()):,}: {share.percent()}")
        for ratio in ratios:
            right = _branch(rows, a, ratio)
            base = _branch(rows, MODEL, ratio)
            entered = int((right >= 0).sum())
            n_right = int((right == 1).sum())
            paired = S.mcnemar(right == 1, base == 1) if a != MODEL else None
            row[f"right_{ratio}"] = n_right
            row[f"entered_{ratio}"] = entered
            wilson = S.proportion_ci(n_right, entered)
            interval = "" if entered == 0 else f" [{S.number(wilson.low, 2)}, {S.number(wilson.high, 2)}]"
            cells.append(f"{n_right}/{entered}{interval}" + ("" if paired is None else f" (p {S.number(paired.p, 2)})"))
        summary.append(row)
        lines.append(cells)
    headers = ["condition", "exp. 1 runs", "KM median survival (s)", "alive at cap", "restricted mean (s)",
               "log-rank p vs declared", "exp. 1 act periods: moving (mean share a run, 95% CI)"]  # fmt: skip
    headers += [f"3.2 {_ratio(r)}: right first / entered (Wilson 95% CI; McNemar p)" for r in ratios]
    right = ", ".join(f"{r} of {TMAZE_TESTS} at ratio {ratio:g}" for ratio, (_, r) in PAPER_TMAZE.items())
    said = (f"The paper: experiment 1's A lived a median of {PAPER_SURVIVAL['A'][0]:,} s (beyond its own 4 h "
            f"cap); in experiment 3.2 the animat entered the right branch (E and Ep) first in {right}.  ")  # fmt: skip
    note = (f"\n{said if paper else ''}A p value compares a condition with the declared animat (log-rank "
            "on survival, McNemar on the right branch test by test); none of these is a claim of the "
            "paper.  Act periods: the control periods of experiment 1's runs spent in ReloadE or "
            f"ReloadEp, and the share of them in which the animat moved more than {bg.MOVING * 100:g} cm, "
            "measured on the world's pose (the paper's animat stops to eat and digest).\n")  # fmt: skip
    return summary, R.markdown_table(headers, lines) + note


def _ratio(condition: float | str) -> str:
    """A T-maze condition's column: its branch ratio, or the user's floor by name."""
    return f"ratio {condition:g}" if isinstance(condition, float) else str(condition)


def _branch(rows: list[dict], ablation: str, ratio) -> np.ndarray:
    """Per test of one condition and ratio, in run order: 1 right first, 0 left first, -1 neither."""
    sel = sorted((r for r in rows if r.get("ablation") == ablation and r.get("experiment") == "bg-tmaze"
                  and r["condition"] == ratio), key=lambda r: r["run"])  # fmt: skip
    return np.array([1 if r["branch"] == "right" else 0 if r["branch"] == "left" else -1 for r in sel])


def _plot(rows: list[dict], path: Path) -> None:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 4))
    for k, a in enumerate(ABLATIONS):
        x = [r["survival_seconds"] / 3600 for r in rows if r.get("ablation") == a and "survival_seconds" in r]
        ax.scatter(np.full(len(x), k) + np.linspace(-0.2, 0.2, len(x)), x, alpha=0.7)
        ax.plot([k - 0.3, k + 0.3], [np.median(x)] * 2, "k-")
    ax.set_xticks(range(len(ABLATIONS)), list(ABLATIONS), rotation=30, ha="right", fontsize=7)
    ax.set_ylabel("experiment 1, condition A: survival (h)")
    ax.set_title("bg ablations")
    save_figure(fig, path)
