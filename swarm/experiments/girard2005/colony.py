"""`swarm experiment bg-colony`: survival against colony size, with and
without a shared map (the paper has one animat).

N animats (condition A: taxon + topological navigation) live in bg-colony
(bg-exp1's floor) from a nest in the east passage, each until it dies or
4 h pass.  With sharing, every animat publishes its map and what its places
hold each tick and merges the others' (agents/controllers/bg/colony.py);
without, each maps alone and the others are only bodies in its way.  A run's
unit is the colony: its animats' mean survival (they are not independent of
each other); sharing against not is a Mann-Whitney U test per size over
those means.  One animat (N = 1) has no one to share with: it runs once per
seed, the baseline (it is experiment 1's condition A from the nest's first
place, bg-exp1's start).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from swarm.core.errors import ScenarioError
from swarm.core.plots import pyplot, save_figure
from swarm.experiments.runner import Outputs, batch_run
from swarm.scenario import load_scenario

SIZES = (1, 2, 4, 8)
REPS = 5
# The nest: two columns of four places, 0.6 m apart, facing north (bg-colony.toml lists the first four).
NEST = ((5.9, 4.5), (6.5, 4.5), (5.9, 3.9), (6.5, 3.9), (5.9, 5.1), (6.5, 5.1), (5.9, 3.3), (6.5, 3.3))


def colony_scenario(size: int, share: bool, seed: int, max_ticks: int | None = None, floor: str | None = None):
    """bg-colony with `size` animats at the nest's first places, sharing or not (and a shorter cap); or `floor`
    (--scenario) with its first group's animats, at its first `size` starts (drawn where it gives fewer)."""
    if not 1 <= size <= len(NEST):
        raise ScenarioError("command line", "--sizes", f"colonies of 1 to {len(NEST)} animats (the nest's places)")
    s = load_scenario(floor or "bg-colony")
    g = s.groups[0]
    if floor is None:
        starts: tuple | None = tuple((x, y, math.pi / 2) for x, y in NEST[:size])
    else:
        starts = g.starts[:size] if g.starts and len(g.starts) >= size else None  # None: drawn with its clearance
    if g.controller != "bg":
        raise ScenarioError(s.source, "group", f"bg-colony needs a first [[group]] of bg animats, not {g.controller}")
    group = dataclasses.replace(g, count=size, starts=starts)
    params = dict(s.controller_params)
    params["bg"] = {**params.get("bg", {}), "share": share}
    return dataclasses.replace(
        s,
        groups=(group,),
        controller_params=params,
        seed=seed,
        max_ticks=s.max_ticks if max_ticks is None else max_ticks,
    )


def run_colony(job: tuple) -> dict:
    """One colony until every animat is dead or 4 h pass: (size, share, run, seed, max_ticks[, floor])."""
    from swarm.engines.arena import ArenaEngine

    size, share, run, seed, max_ticks, *floor = job
    engine = ArenaEngine(colony_scenario(size, share, seed, max_ticks, *floor))
    summary = engine.run()
    robots = summary["robots"]
    lives = np.array([r["survival_seconds"] for r in robots])
    maps = [r.get("map") or {} for r in robots]
    return {"size": size, "share": share, "run": run, "seed": seed, "mean_s": round(float(lives.mean()), 2),
            "median_s": float(np.median(lives)), "first_death_s": float(lives.min()), "last_s": float(lives.max()),
            "alive_at_cap": int(sum(r["alive"] for r in robots)),
            "lives_s": " ".join(f"{x:g}" for x in lives),
            "nodes": round(float(np.mean([m.get("nodes", 0) for m in maps])), 1),
            "from_others": round(float(np.mean([m.get("from_others", 0) for m in maps])), 1),
            "merged_with_ours": round(float(np.mean([m.get("merged_with_ours", 0) for m in maps])), 1),
            "holds_heard": round(float(np.mean([m.get("holds_heard", 0) for m in maps])), 1),
            "rejected_shared": engine.refused_shared, "wall_seconds": summary["wall_seconds"]}  # fmt: skip


def _summary(rows: list[dict], paper: bool = True) -> tuple[list[dict], str]:
    from scipy.stats import mannwhitneyu

    summary, lines = [], []
    for size in sorted({r["size"] for r in rows}):
        means = {}
        for share in (False, True):
            sel = [r for r in rows if r["size"] == size and r["share"] == share]
            if not sel:
                continue
            colony = np.array([r["mean_s"] for r in sel])
            lives = np.array([float(x) for r in sel for x in r["lives_s"].split()])
            means[share] = colony
            summary.append({"size": size, "share": share, "runs": len(sel), "colony_mean_median_s":
                            float(np.median(colony)), "animat_median_s": float(np.median(lives)),
                            "animat_min_s": float(lives.min()), "animat_max_s": float(lives.max()),
                            "alive_at_cap": int(sum(r["alive_at_cap"] for r in sel)),
                            "from_others": float(np.mean([r["from_others"] for r in sel])),
                            "holds_heard": float(np.mean([r["holds_heard"] for r in sel]))})  # fmt: skip
            lines.append(f"| {size} | {'yes' if share else 'no'} | {len(sel)} | {np.median(colony):.0f} | "
                         f"{np.median(lives):.0f} | {lives.min():.0f} : {lives.max():.0f} | "
                         f"{sum(r['alive_at_cap'] for r in sel)} / {len(lives)} | "
                         f"{np.mean([r['nodes'] for r in sel]):.0f} | {np.mean([r['from_others'] for r in sel]):.0f} | "
                         f"{np.mean([r['holds_heard'] for r in sel]):.0f} |")  # fmt: skip
        if len(means) == 2 and min(len(m) for m in means.values()) >= 2:
            test = mannwhitneyu(means[True], means[False], alternative="two-sided")
            summary.append({"size": size, "share": "U test", "u": float(test.statistic), "p": float(test.pvalue)})
            lines.append(f"| {size} | U = {test.statistic:.1f}, p = {test.pvalue:.3g} | | | | | | | | |")
    md = ("| animats | shared map | runs | colony mean survival, median (s) | animat median (s) | animat range (s) | "
          "alive at 4 h | nodes per animat | of them from others | place weights heard |\n"
          "|---|---|---|---|---|---|---|---|---|---|\n" + "\n".join(lines) + "\n\n"
          "A colony's mean survival is its animats' mean; the U test (two-sided) compares those means with and "
          "without the shared map." + ("  One animat alone is experiment 1's condition A (the paper: median "
          "14431.5 s)." if paper else "") + "\n")  # fmt: skip
    return summary, md


def _plot(rows: list[dict], path: Path) -> None:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 4))
    sizes = sorted({r["size"] for r in rows})
    for share, marker, offset in ((False, "o", -0.08), (True, "s", 0.08)):
        xs, ys, med = [], [], []
        for k, size in enumerate(sizes):
            sel = [r["mean_s"] / 3600 for r in rows if r["size"] == size and (r["share"] == share or size == 1)]
            xs += [k + offset] * len(sel)
            ys += sel
            med.append(np.median(sel))
        ax.scatter(xs, ys, marker=marker, alpha=0.6, label=f"{'shared' if share else 'own'} map")
        ax.plot(np.arange(len(sizes)) + offset, med, "-")
    ax.set_xticks(range(len(sizes)), [str(s) for s in sizes])
    ax.set(xlabel="animats in the colony", ylabel="colony mean survival (h)", title="bg-colony (4 h cap)")
    ax.legend()
    save_figure(fig, path)


def run_colony_experiment(name: str, sizes: tuple[int, ...] | None, reps: int | None, jobs: int | None, seed: int,
                          out: Path | None, progress: bool = True, max_ticks: int | None = None,
                          scenario: str | None = None) -> dict:  # fmt: skip
    """`name`: "bg-colony", the one experiment this runs (the registry calls every experiment by name);
    `scenario`: another floor with what experiment 1 needs (bg.check_floors) and a group of bg animats."""
    from swarm.experiments.girard2005.bg import check_floors

    sizes = tuple(sorted(set(sizes or SIZES)))
    reps = REPS if reps is None else reps
    if scenario is not None:
        check_floors("bg-colony", scenario, None, {})
    for size in sizes:
        colony_scenario(size, False, seed, None, scenario)  # one clear line for a size the nest cannot hold
    out = Outputs(out, "bg-colony")
    work = [(n, share, k, seed + k, max_ticks, scenario) for n in sorted(sizes, reverse=True)
            for share in ((False,) if n == 1 else (False, True)) for k in range(reps)]  # fmt: skip
    rows = batch_run(run_colony, work, jobs=jobs, desc="bg-colony", progress=progress)
    rows.sort(key=lambda r: (r["size"], r["share"], r["run"]))
    out.runs(rows, list(rows[0]))
    summary, md = _summary(rows, paper=scenario is None)
    cap = "4 h" if scenario is None else "the floor's max_ticks"
    where = ("bg-colony (bg-exp1's floor, a nest in the east passage)" if scenario is None else
             f"the user's floor {scenario} (--scenario; its group's starts, drawn where it gives fewer), not the "
             "paper's: the paper's number is not shown")  # fmt: skip
    text = (f"# A colony of BG animats: survival against colony size, with and without a shared map\n\n{reps} runs "
            f"per size and condition, at most {cap}; seeds {seed}..{seed + reps - 1}; {where}.\n\n" + md)  # fmt: skip
    result = out.finish(summary, text)
    _plot(rows, out / "plot.png")
    return result
