"""`swarm experiment tuning`: both foraging models tuned with the same budget, on development seeds only.

The paper tuned its ant model ("we computed several simulations to tune diffusion and evaporation
rates in order to obtain the best possible performances") and gives no budget.  We give each model
the same one: 25 settings of its free parameters, each run on setup 3 (50 agents) at sizes 25, 50
and 100 on the same 10 development seeds (750 runs a model).  The score of a setting is the
geometric mean over the sizes of its mean foraging time, so each size weighs the same.  The chosen
settings are the models' declared defaults ([ant] and [cmarking] in world_server/grid/scenario.py);
reported numbers come from the confirmation seeds (`swarm reproduce simonin2007`), never these.

- ant (NetLogo's Ants model): wiggle (degrees) × threshold, the lower end of the pheromone window in
  which an ant sniffs for a stronger scent; the window's upper end is 40 × threshold, NetLogo's
  [0.05, 2).  Diffusion 95% and evaporation 0.5% are the paper's and stay.
- cmarking: climb_patience, the one parameter the paper does not fix (rule 9 of docs/cmarking.md).
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np

from swarm.core.errors import ScenarioError
from swarm.core.plots import pyplot, save_figure
from swarm.experiments.protocol import CONFIRMATION_SEEDS
from swarm.experiments.runner import Outputs, batch_run
from swarm.experiments.simonin2007.floors import Floor, floor_note, user_floor

SIZES = (25, 50, 100)
SEEDS = 10
WIGGLES = (0, 10, 20, 40, 80)
THRESHOLDS = (0.001, 0.01, 0.03, 0.1, 0.3)
WINDOW = 40.0  # NetLogo's pheromone window [0.05, 2): its upper end is 40 times its lower end
PATIENCES = (1, 2, 3, 4, 5, 6, 8, 10, 12, 14, 16, 18, 20, 22, 25, 30, 35, 40, 50, 60, 80, 100, 150, 200, 400)
CAP = 200_000  # a setting whose runs reach this is scored at it (and counted unfinished)
FIELDS = ["controller", "setting", "wiggle", "threshold", "ceiling", "climb_patience", "size", "seed", "iterations",
          "finished", "wall_seconds"]  # fmt: skip


def settings() -> list[tuple[str, dict]]:
    """(controller, its parameters) for every setting of both models: 25 each."""
    ants = [("ant", {"wiggle": w, "threshold": t, "ceiling": WINDOW * t}) for w in WIGGLES for t in THRESHOLDS]
    return ants + [("cmarking", {"climb_patience": p}) for p in PATIENCES]


def label(controller: str, params: dict) -> str:
    if controller == "ant":
        return f"wiggle {params['wiggle']}, threshold {params['threshold']:g}"
    return f"climb_patience {params['climb_patience']}"


def run_setting(job: tuple) -> dict:
    from swarm.engines.grid import Engine
    from swarm.scenario import load_scenario

    controller, params, size, seed, floor = job
    s = load_scenario(floor).with_overrides(agents=50, controller=controller, seed=seed)
    if controller == "ant":
        s = replace(s, ant=replace(s.ant, **params))
    else:
        s = replace(s, cmarking=replace(s.cmarking, **params))
    summary = Engine(s).run("foraged", CAP).summary
    return {"controller": controller, "setting": label(controller, params), **params, "size": size, "seed": seed,
            "iterations": summary["iterations"], "finished": summary["finished"],
            "wall_seconds": summary["wall_seconds"]}  # fmt: skip


def score(rows: list[dict], sizes: tuple[int, ...]) -> dict[str, float]:
    """Each setting's geometric mean over the sizes of its mean foraging time (lower is better)."""
    out = {}
    for setting in dict.fromkeys(r["setting"] for r in rows):
        means = [np.mean([r["iterations"] for r in rows if r["setting"] == setting and r["size"] == s]) for s in sizes]
        out[setting] = float(math.exp(np.mean(np.log(means))))
    return out


def sizes_option(text: str) -> tuple[int, ...]:
    try:
        sizes = tuple(int(v) for v in text.split(","))
    except ValueError:
        raise ValueError(f"expected sizes like 25,50,100, got {text!r}") from None
    if not sizes or any(not 5 <= s <= 4096 for s in sizes):
        raise ValueError(f"expected sizes from 5 to 4096, got {text!r}")
    return sizes


def run_tuning(name: str, reps: int | None, jobs: int | None, seed: int, out: Path | None,
               progress: bool = True, tuning_sizes: tuple[int, ...] | None = None,
               scenario: str | None = None) -> dict:  # fmt: skip
    """`name`: "tuning" (the registry calls every experiment by name).  Tunes on setup 3's `tuning_sizes`, or
    on the one grid floor `scenario` names (floors.user_floor)."""
    reps = SEEDS if reps is None else reps
    if scenario is not None and tuning_sizes is not None:
        raise ScenarioError("command line", "--tuning-sizes", "--scenario gives the one floor to tune on; "
                            "--tuning-sizes chooses setup 3's sizes: give one or the other")  # fmt: skip
    floor = None if scenario is None else user_floor(name, scenario)
    sizes = (floor.size,) if floor else SIZES if tuning_sizes is None else tuning_sizes
    refs = {s: floor.ref if floor else f"setup3-{s}" for s in sizes}
    if seed + reps > CONFIRMATION_SEEDS.start:
        last = seed + reps - 1
        raise ScenarioError("command line", "--seed", f"tuning uses development seeds only (below "
                            f"{CONFIRMATION_SEEDS.start}); seeds {seed}..{last} reach past them")  # fmt: skip
    out_ = Outputs(out, name)
    work = [(c, p, size, seed + k, refs[size]) for c, p in settings() for size in sizes for k in range(reps)]
    work.sort(key=lambda j: j[2] ** 2 * (3 if j[0] == "ant" else 1), reverse=True)  # the longest first
    rows = batch_run(run_setting, work, jobs=jobs, desc=name, progress=progress)
    order = [label(c, p) for c, p in settings()]
    rows.sort(key=lambda r: (order.index(r["setting"]), r["size"], r["seed"]))
    out_.runs(rows, FIELDS)
    summary, md = _table(rows, reps, seed, sizes, floor)
    result = out_.finish(summary, md)
    _plot(rows, out_ / "plot.png", sizes)
    return result


def _table(rows: list[dict], reps: int, seed: int, sizes: tuple[int, ...],
           floor: Floor | None = None) -> tuple[list[dict], str]:  # fmt: skip
    scores = score(rows, sizes)
    summary, parts = [], []
    for controller in ("ant", "cmarking"):
        mine = [s for s in scores if any(r["setting"] == s and r["controller"] == controller for r in rows)]
        best = min(mine, key=scores.__getitem__)
        columns = [f"{s}x{s}" if floor is None or floor.paper else floor.label for s in sizes]
        lines = [f"\n### {controller}\n", "| setting | " + " | ".join(columns)
                 + " | geometric mean | unfinished |", "|---|" + "---|" * (len(sizes) + 2)]  # fmt: skip
        for setting in mine:
            sel = [r for r in rows if r["setting"] == setting]
            means = [np.mean([r["iterations"] for r in sel if r["size"] == s]) for s in sizes]
            unfinished = sum(not r["finished"] for r in sel)
            mark = " **best**" if setting == best else ""
            lines.append(f"| {setting}{mark} | " + " | ".join(f"{m:,.0f}" for m in means)
                         + f" | {scores[setting]:,.0f} | {unfinished}/{len(sel)} |")  # fmt: skip
            summary.append({"controller": controller, "setting": setting, "score": round(scores[setting], 1),
                            **{f"mean_{s}": round(float(m), 1) for s, m in zip(sizes, means, strict=True)},
                            "unfinished": unfinished, "best": setting == best})  # fmt: skip
        parts.append("\n".join(lines))
    head = (f"# Tuning both foraging models with the same budget (development seeds {seed}..{seed + reps - 1})\n\n"
            + (f"25 settings per model × sizes {', '.join(map(str, sizes))} (setup 3, 50 agents)" if floor is None
               else f"{floor_note(floor, numbers=False)}25 settings per model on {floor.label} (50 agents)")
            + f" × {reps} seeds; score: the geometric mean over the sizes of the mean foraging time (lower is "
            f"better). The ants' pheromone window is [threshold, {WINDOW:g} × threshold), NetLogo's [0.05, 2) "
            "scaled.\n")  # fmt: skip
    return summary, head + "\n".join(parts) + "\n"


def _plot(rows: list[dict], path: Path, sizes: tuple[int, ...]) -> None:
    plt = pyplot()
    scores = score(rows, sizes)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    grid = np.array([[scores[f"wiggle {w}, threshold {t:g}"] for t in THRESHOLDS] for w in WIGGLES])
    im = axes[0].imshow(np.log10(grid), cmap="viridis_r")
    axes[0].set(xticks=range(len(THRESHOLDS)), xticklabels=[f"{t:g}" for t in THRESHOLDS], xlabel="threshold",
                yticks=range(len(WIGGLES)), yticklabels=[str(w) for w in WIGGLES], ylabel="wiggle (degrees)",
                title="ant: log10 score (lower is better)")  # fmt: skip
    fig.colorbar(im, ax=axes[0])
    axes[1].plot(PATIENCES, [scores[f"climb_patience {p}"] for p in PATIENCES], "o-")
    axes[1].set(xscale="log", xlabel="climb_patience", ylabel="score (iterations)", title="cmarking")
    save_figure(fig, path)
