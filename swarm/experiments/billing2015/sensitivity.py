"""`swarm experiment dft-sensitivity`: how SPA's success in case 2 (the large maze) moves with the
proximity and IR parameters and the map noise, one parameter at a time.

Every condition runs the dft controller on the same start/goal pairs with the same seeds as
`dft-case2`'s SPA-LN condition (its pairs and its run function, dft.pair_jobs and carrot.run_pair),
with exactly one declared parameter (agents/controllers/dft/params.py) set to another level and
everything else as declared.  The declared level is one condition shared by every parameter, so each
other level is compared with it pair by pair: the success share with its Wilson 95% interval, the
exact McNemar test against the declared level, the median ticks to goal among successes.

A level is set for the length of one run in the worker that runs it, by handing the controller module
a parameter class (or map-noise table) with that one field changed; at the declared level nothing is
changed, so those rows are `dft-case2`'s rows.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, fields
from functools import partial
from pathlib import Path

import numpy as np

from swarm.core.errors import ScenarioError
from swarm.core.plots import pyplot, save_figure
from swarm.experiments.billing2015.carrot import RUN_FIELDS, fmt, run_pair
from swarm.experiments.billing2015.dft import pair_jobs
from swarm.experiments.protocol import CONFIRMATION_SEEDS, DEVELOPMENT_SEEDS
from swarm.experiments.runner import Outputs, batch_run
from swarm.experiments.stats import mcnemar, proportion_ci

NAME = "dft-sensitivity"
SCENARIO = "large-maze"
NOISE = "low"  # SPA-LN: the condition whose failures include the proximity inhibition alone (docs/dft.md, case 2)
SEED_BANDS = {"development": DEVELOPMENT_SEEDS, "confirmation": CONFIRMATION_SEEDS}
REPS = 6  # pairs per condition: 11 conditions, about 10 minutes on 2 cores (8 pairs took 14 min)


@dataclass(frozen=True)
class Swept:
    """One declared parameter and the levels it is run at (the declared one among them)."""

    name: str  # the experiment's name for it (--parameter)
    cls: str  # SpaParams, Interface or MapNoise
    field: str
    levels: tuple[float, ...]
    why: str


# One at a time round the declared value.  The proximity inhibition's gain and width have no number in the
# paper (the code's), so they are halved and doubled; c_prox and sigma_prox are Table 2's, halved and doubled
# too (the paper gives no range for them).  The map noise at the low level (0.05) is run at the code's other
# two levels, the "none" (0.005) and "high" (1.0) noise levels' map noise, with the low level's position
# noise: the map's part of the noise alone.
SWEPT = (
    Swept("prox_gain", "SpaParams", "prox_gain", (-8.0, -16.0, -32.0),
          "proximity inhibition S_O onto the action fields (code: -16, no number in the paper): x0.5, x2"),
    Swept("prox_width", "SpaParams", "prox_sigma", (6.0, 12.0, 24.0),
          "width of S_O's Gaussian in cells (code: 12, no number in the paper): x0.5, x2"),
    Swept("c_prox", "Interface", "prox_strength", (2.5, 5.0, 10.0),
          "IR strength c_prox in c_prox ln(1 + p/50), eq. 17 (Table 2: 5): x0.5, x2"),
    Swept("ir_width", "Interface", "prox_sigma", (1.5, 3.0, 6.0),
          "width sigma_prox of each IR sensor's bump in the proximity field (Table 2: 3 cells): x0.5, x2"),
    Swept("map_noise", "MapNoise", "low", (0.005, 0.05, 1.0),
          "map noise std at the low noise level (paper and code: 0.05); the code's none and high levels"),
)  # fmt: skip
BY_NAME = {s.name: s for s in SWEPT}
FIELDS = ["parameter", "level", "declared_level", *RUN_FIELDS]


def declared_value(s: Swept) -> float:
    from agents.controllers.dft import params

    (f,) = [f for f in fields(getattr(params, s.cls)) if f.name == s.field]
    return float(f.default)


@contextmanager
def level_set(name: str, value: float) -> Iterator[None]:
    """Within: the dft controller built by this process sees parameter `name` at `value`, every other
    parameter as declared.  At the declared value it changes nothing."""
    from agents.controllers.dft import controller

    s = BY_NAME[name]
    if value == declared_value(s):
        yield
        return
    saved = controller.SpaParams, controller.Interface, controller.MAP_NOISE
    try:
        if s.cls == "MapNoise":
            controller.MAP_NOISE = {**saved[2], s.field: value}
        else:
            cls = saved[0] if s.cls == "SpaParams" else saved[1]
            setattr(controller, s.cls, partial(cls, **{s.field: value}))
        yield
    finally:
        controller.SpaParams, controller.Interface, controller.MAP_NOISE = saved


def run_level(job: tuple) -> dict:
    """One dft-case2 run (carrot.run_pair's job) with one parameter at one level."""
    name, value, pair_job = job
    with level_set(name, value):
        row = run_pair(pair_job)
    return {"parameter": name, "level": value, "declared_level": value == declared_value(BY_NAME[name]), **row}


def plan(parameters: list[str], reps: int, seed: int, max_ticks: int | None) -> list[tuple]:
    """The declared level once (under the first parameter's name), then every other level of each parameter,
    each on dft-case2's SPA-LN jobs: the same pairs and seeds for every condition."""
    case2 = [j for j in pair_jobs("dft-case2", reps, seed, max_ticks) if j[9] == "dft" and j[1] == NOISE]
    first = BY_NAME[parameters[0]]
    work = [(first.name, declared_value(first), j) for j in case2]
    for p in parameters:
        s = BY_NAME[p]
        work += [(p, v, j) for v in s.levels if v != declared_value(s) for j in case2]
    return work


def summarise(rows: list[dict], parameters: list[str]) -> tuple[list[dict], str]:
    base = sorted((r for r in rows if r["declared_level"]), key=lambda r: r["pair"])
    summary, lines = [], []
    for p in parameters:
        s = BY_NAME[p]
        for v in s.levels:
            declared = v == declared_value(s)
            sel = base if declared else sorted((r for r in rows if r["parameter"] == p and r["level"] == v),
                                               key=lambda r: r["pair"])  # fmt: skip
            ok = [bool(r["reached"]) for r in sel]
            share = proportion_ci(sum(ok), len(ok))
            ticks = [r["ticks_to_goal"] for r in sel if r["reached"] and r["ticks_to_goal"] not in (None, "")]
            test = None if declared else mcnemar(ok, [bool(r["reached"]) for r in base])
            summary.append({"parameter": p, "level": v, "declared": declared, "runs": len(sel),
                            "reached": sum(ok), "share": round(share.value, 4),
                            "share_low": round(share.low, 4), "share_high": round(share.high, 4),
                            "only_here": int(test.statistic) if test else None,
                            "mcnemar_p": round(test.p, 4) if test else None,
                            "ticks_to_goal_median": float(np.median(ticks)) if ticks else None})  # fmt: skip
            lines.append(f"| {p} | {v:g}{' (declared)' if declared else ''} | {sum(ok)}/{len(sel)} | "
                         f"{share.text(2)} | {'–' if declared else fmt(test.p, 3)} | "
                         f"{fmt(float(np.median(ticks)) if ticks else math.nan, 0)} |")  # fmt: skip
    head = ("| parameter | level | reached | share [Wilson 95%] | McNemar p (exact, vs declared) | "
            "median ticks to goal (reached) |\n|---|---|---|---|---|---|\n")  # fmt: skip
    return summary, head + "\n".join(lines) + "\n"


def plot(summary: list[dict], parameters: list[str], path: Path) -> None:
    plt = pyplot()
    fig, axes = plt.subplots(1, len(parameters), figsize=(3.2 * len(parameters), 3.4), squeeze=False)
    for ax, p in zip(axes[0], parameters, strict=True):
        sel = [r for r in summary if r["parameter"] == p]
        x = np.arange(len(sel))
        y = np.array([r["share"] for r in sel])
        err = np.array([[r["share"] - r["share_low"] for r in sel], [r["share_high"] - r["share"] for r in sel]])
        ax.errorbar(x, y, yerr=err, fmt="o-", capsize=3, color="#c63")
        for i, r in enumerate(sel):
            if r["declared"]:
                ax.plot(i, r["share"], "ks", ms=7, mfc="none")
        ax.set_xticks(x, [f"{r['level']:g}" for r in sel])
        ax.set(title=p, ylim=(-0.05, 1.05), xlabel="level", ylabel="success share" if p == parameters[0] else None)
    save_figure(fig, path)


def run_sensitivity(name: str, scenario: str | None, reps: int | None, jobs: int | None, seed: int,
                    out: Path | None, parameter: str | None = None, max_ticks: int | None = None,
                    progress: bool = True) -> dict:  # fmt: skip
    if scenario not in (None, SCENARIO):
        raise ScenarioError("command line", "--scenario", f"{name} runs on {SCENARIO} (the paper's case 2)")
    if parameter is not None and parameter not in BY_NAME:
        raise ScenarioError("command line", "--parameter", f"{parameter!r} is not swept: one of {', '.join(BY_NAME)}")
    reps = REPS if reps is None else reps
    # seed draws the pairs and pair k runs on seed + k (dft.pair_jobs): all of them in one range
    band = next((b for b, pool in SEED_BANDS.items() if seed in pool and seed + reps in pool), None)
    if band is None:
        raise ScenarioError("command line", "--seed", f"{name} runs its pairs' seeds within one range: development "
                            "(0 to 9999) to explore, confirmation (10000 to 19999) to report")  # fmt: skip
    parameters = [parameter] if parameter else list(BY_NAME)
    out = Outputs(out, name)
    rows = batch_run(run_level, plan(parameters, reps, seed, max_ticks), jobs=jobs, desc=name, progress=progress)
    out.runs(rows, FIELDS)
    summary, md = summarise(rows, parameters)
    plot(summary, parameters, out / "plot.png")
    levels = "\n".join(f"- {s.name} ({s.cls}.{s.field}): {', '.join(f'{v:g}' for v in s.levels)}; {s.why}"
                       for s in SWEPT if s.name in parameters)  # fmt: skip
    title = (f"# Sensitivity of SPA in case 2 (large maze, {NOISE} noise), one parameter at a time\n\n"
             f"{reps} start/goal pairs per condition, the same pairs and seeds in every condition "
             f"(dft-case2's); pairs drawn from seed {seed}, run on seeds {seed + 1}..{seed + reps} ({band} seeds); "
             f"at most {max_ticks or 3000} steps of 64 ms.\n\n"
             f"{levels}\n\n")  # fmt: skip
    return out.finish(summary, title + md)
