"""`swarm experiment`: the paper's tables, rerun on our engine.

Each experiment is a list of runs (scenario, agents, controller, seed); the
runs go to a process pool, and the results land in runs.csv (one row per
run), summary.csv (one row per configuration), table.md (the paper's numbers
beside ours, with the ratio) and plot.png.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from swarm.core.plots import pyplot, save_figure
from swarm.experiments.report import markdown_table
from swarm.experiments.runner import Outputs, batch_run, cross
from swarm.experiments.simonin2007 import paper
from swarm.experiments.simonin2007.floors import Floor, floor_note, user_floor

RUN_FIELDS = ["experiment", "scenario", "size", "agents", "controller", "physics", "seed", "iterations", "finished",
              "blocked_share", "blocked_moves", "wall_seconds"]  # fmt: skip


@dataclass(frozen=True)
class Config:
    """One configuration of an experiment; it runs once per seed."""

    scenario: str
    size: int  # side of the grid, for tables over sizes
    agents: int
    controller: str = "cmarking"
    physics: str = "ideal"


@dataclass(frozen=True)
class RunSpec:
    experiment: str
    scenario: str
    size: int
    agents: int
    controller: str
    physics: str
    seed: int
    max_iterations: int


@dataclass(frozen=True)
class Experiment:
    name: str
    title: str
    default_reps: int
    configs: Callable[..., list[Config]]  # (floor: Floor | None) -> its conditions, on the paper's floor for None
    max_iterations: int
    report: Callable[..., tuple[list[dict], str]]  # (rows, floor: Floor | None)
    plot: Callable[..., None]  # (rows, path, floor: Floor | None)


def run_one(spec: RunSpec) -> dict:
    from swarm.engines.grid import Engine
    from swarm.scenario import load_scenario

    scenario = load_scenario(spec.scenario).with_overrides(
        agents=spec.agents, controller=spec.controller, seed=spec.seed, physics=spec.physics
    )
    s = Engine(scenario).run("foraged", spec.max_iterations).summary
    return {
        "experiment": spec.experiment,
        "scenario": spec.scenario,
        "size": spec.size,
        "agents": spec.agents,
        "controller": spec.controller,
        "physics": spec.physics,
        "seed": spec.seed,
        "iterations": s["iterations"],
        "finished": s["finished"],
        "blocked_share": s.get("blocked_share", 0.0),
        "blocked_moves": s.get("blocked_moves", 0),
        "wall_seconds": s["wall_seconds"],
    }


def _stats(rows: list[dict], **match) -> tuple[float, float, int, int]:
    sel = [r for r in rows if all(r[k] == v for k, v in match.items())]
    its = np.array([r["iterations"] for r in sel], dtype=float)
    unfinished = sum(not r["finished"] for r in sel)
    if len(its) == 0:
        return float("nan"), float("nan"), 0, 0
    return float(its.mean()), float(its.std()), len(its), unfinished


def _fmt(x: float, digits: int = 1) -> str:
    return "n/a" if x != x else f"{x:,.{digits}f}"


def _shown(floor: Floor | None) -> bool:
    """The paper's numbers apply: the experiment runs on the paper's own floor."""
    return floor is None or floor.paper


def _on(floor: Floor | None, ref: str, size: int) -> tuple[str, int]:
    """The floor's reference and side: the user's floor, else the paper's (`ref`, `size`)."""
    return (ref, size) if floor is None else (floor.ref, floor.size)


def _table1_configs(floor: Floor | None = None):
    ref, size = _on(floor, "setup1", 40)
    return [Config(ref, size, n) for n in paper.TABLE1]


def _table1_report(rows, floor: Floor | None = None):
    shown, summary, lines, prev = _shown(floor), [], [], None
    for n, (p_mean, p_std) in paper.TABLE1.items():
        mean, std, count, unfinished = _stats(rows, agents=n)
        halving = mean / prev if prev else float("nan")
        prev = mean
        row = {"agents": n, "runs": count, "unfinished": unfinished, "mean": round(mean, 1), "std": round(std, 1)}
        line = [str(n), _fmt(mean), _fmt(std)]
        if shown:
            row |= {"paper_mean": p_mean, "paper_std": p_std, "ratio_to_paper": round(mean / p_mean, 3)}
            line += [str(p_mean), str(p_std), f"{mean / p_mean:.2f}"]
        summary.append(row | {"ratio_to_previous": round(halving, 3)})
        lines.append([*line, _fmt(halving, 2), f"{unfinished}/{count}"])
    papers = ["paper: mean", "paper: std", "ours/paper"] if shown else []
    md = markdown_table(["agents", "ours: mean", "ours: std", *papers, "ours: T(n)/T(n/2)", "unfinished"], lines)
    return summary, md


def _table1_plot(rows, path, floor: Floor | None = None):
    plt = pyplot()
    ns = list(paper.TABLE1)
    ours = [_stats(rows, agents=n) for n in ns]
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.errorbar(ns, [o[0] for o in ours], yerr=[o[1] for o in ours], marker="o", capsize=3, label="swarm")
    if _shown(floor):
        ax.errorbar(ns, [paper.TABLE1[n][0] for n in ns], yerr=[paper.TABLE1[n][1] for n in ns],
                    marker="s", capsize=3, label="paper (Table 1)")  # fmt: skip
    title = "Setup 1: 40x40, 30% obstacles, 20 resources" if floor is None else floor.label
    ax.set(xscale="log", yscale="log", xlabel="agents", ylabel="iterations to forage", title=title)
    ax.legend()
    save_figure(fig, path)


# --------------------------------------------------------------------- table 2


def _table2_configs(floor: Floor | None = None):
    ref, size = _on(floor, "setup2", 20)
    return [Config(ref, size, n) for n in paper.TABLE2]


def _table2_report(rows, floor: Floor | None = None):
    v_ref = _stats(rows, agents=1)[0]
    p_ref = paper.TABLE2[1]
    shown, summary, lines = _shown(floor), [], []
    for n, p_exp in paper.TABLE2.items():
        mean, std, count, unfinished = _stats(rows, agents=n)
        proj, p_proj = v_ref / n, p_ref / n
        sem = std / np.sqrt(count) if count else float("nan")
        row = {"agents": n, "runs": count, "unfinished": unfinished, "mean": round(mean, 1), "sem": round(sem, 1),
               "projected": round(proj, 1), "difference": round(proj - mean, 1)}  # fmt: skip
        line = [str(n), f"{_fmt(mean)} ± {_fmt(sem)}", _fmt(proj), _fmt(proj - mean)]
        if shown:
            row |= {"paper_mean": p_exp, "paper_projected": round(p_proj, 1),
                    "paper_difference": round(p_proj - p_exp, 1), "ratio_to_paper": round(mean / p_exp, 3)}  # fmt: skip
            line += [_fmt(p_exp), _fmt(p_proj), _fmt(p_proj - p_exp), f"{mean / p_exp:.2f}"]
        summary.append(row)
        lines.append(line)
    papers = ["paper: mean", "paper: projected", "paper: proj-exp", "ours/paper"] if shown else []
    md = markdown_table(["agents", "ours: mean ± s.e.", "ours: projected", "ours: proj-exp", *papers], lines)
    return summary, md


def _table2_plot(rows, path, floor: Floor | None = None):
    plt = pyplot()
    ns = list(paper.TABLE2)
    ours = [_stats(rows, agents=n)[0] for n in ns]
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(ns, ours, "o-", label="swarm: experimental")
    ax.plot(ns, [ours[0] / n for n in ns], "--", label="swarm: projected V_ref/n")
    if _shown(floor):
        ax.plot(ns, [paper.TABLE2[n] for n in ns], "s-", label="paper: experimental")
        ax.plot(ns, [paper.TABLE2[1] / n for n in ns], ":", label="paper: projected")
    title = "Setup 2: 20x20, 5%, 2 resources" if floor is None else floor.label
    ax.set(xlabel="agents", ylabel="iterations to forage", title=title)
    ax.legend()
    save_figure(fig, path)


# --------------------------------------------------------------------- table 3

SETUP3_SIZES = tuple(paper.TABLE3)


def _table3_configs(floor: Floor | None = None):
    """Setup 3's sizes: one floor cannot give them (floors.ONE_FLOOR_REFUSED)."""
    return [Config(f"setup3-{s}", s, 50) for s in SETUP3_SIZES]


def _table3_report(rows, floor: Floor | None = None):
    summary, lines, prev, p_prev = [], [], None, None
    for size, p_mean in paper.TABLE3.items():
        mean, std, count, unfinished = _stats(rows, size=size)
        r = mean / prev if prev else float("nan")
        p_r = p_mean / p_prev if p_prev else float("nan")
        prev, p_prev = mean, p_mean
        summary.append({"size": size, "runs": count, "unfinished": unfinished, "mean": round(mean, 1),
                        "std": round(std, 1), "R": round(r, 3), "paper_mean": p_mean,
                        "paper_R": round(p_r, 3), "ratio_to_paper": round(mean / p_mean, 3)})  # fmt: skip
        lines.append([f"{size}x{size}", _fmt(mean), _fmt(std), _fmt(r, 2), str(p_mean), _fmt(p_r, 2),
                      f"{mean / p_mean:.2f}", f"{unfinished}/{count}"])  # fmt: skip
    md = markdown_table(["size", "ours: mean", "ours: std", "ours: R", "paper: mean", "paper: R", "ours/paper",
              "unfinished"], lines)  # fmt: skip
    return summary, md


def _table3_plot(rows, path, floor: Floor | None = None):
    plt = pyplot()
    sizes = list(paper.TABLE3)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(sizes, [_stats(rows, size=s)[0] for s in sizes], "o-", label="swarm")
    ax.plot(sizes, [paper.TABLE3[s] for s in sizes], "s-", label="paper (Table 3)")
    ax.set(xscale="log", yscale="log", xlabel="side of the square environment",
           ylabel="iterations to forage", title="Setup 3: 50 agents, 5%, 20 resources x 2000")  # fmt: skip
    ax.legend()
    save_figure(fig, path)


# ------------------------------------------------------------------------ ants

ANT_SIZES = (12, 25, 50, 100)


def _ants_configs(floor: Floor | None = None):
    floors = [(f"setup3-{s}", s) for s in ANT_SIZES] if floor is None else [(floor.ref, floor.size)]
    return [Config(ref, s, 50, c) for ref, s in floors for c in ("cmarking", "ant")]


def _size_label(size: int, floor: Floor | None) -> str:
    return f"{size}x{size}" if floor is None or floor.paper else floor.label


def _ants_report(rows, floor: Floor | None = None):
    summary, lines = [], []
    for size in sorted({r["size"] for r in rows}):
        cm, _, cm_n, cm_unf = _stats(rows, size=size, controller="cmarking")
        ant, _, ant_n, ant_unf = _stats(rows, size=size, controller="ant")
        gap = 100 * (1 - cm / ant)
        summary.append({"size": size, "cmarking_mean": round(cm, 1), "ant_mean": round(ant, 1),
                        "gap_percent": round(gap, 1), "cmarking_unfinished": cm_unf,
                        "ant_unfinished": ant_unf, "runs": cm_n, "cmarking_wins": bool(cm < ant)})  # fmt: skip
        lines.append([_size_label(size, floor), _fmt(cm), _fmt(ant), f"{gap:.0f}%", "yes" if cm < ant else "NO",
                      f"{cm_unf}+{ant_unf}/{cm_n + ant_n}"])  # fmt: skip
    md = markdown_table(["size", "c-marking: mean", "ant: mean", "gap 1-cm/ant", "c-marking faster",
              "unfinished"], lines)  # fmt: skip
    if _shown(floor):
        md += (f"\n\nPaper (section 5.5, Figure 9): the gap shrinks "
               f"{' -> '.join(f'{g}%' for g in paper.ANT_GAP_PERCENT)} as the environment grows.")  # fmt: skip
    return summary, md


def _ants_plot(rows, path, floor: Floor | None = None):
    plt = pyplot()
    sizes = sorted({r["size"] for r in rows}) or list(ANT_SIZES)
    fig, ax = plt.subplots(figsize=(6, 4))
    for c in ("cmarking", "ant"):
        ax.plot(sizes, [_stats(rows, size=s, controller=c)[0] for s in sizes], "o-", label=c)
    where = "setup 3" if floor is None else floor.label
    ax.set(xscale="log", yscale="log", xlabel="side of the square environment",
           ylabel="iterations to forage", title=f"c-marking vs ants ({where}, 50 agents)")  # fmt: skip
    ax.legend()
    save_figure(fig, path)


# ------------------------------------------------------------------ congestion

CONGESTION_AGENTS = (10, 20, 40, 80, 160)
CONGESTION_CAP = 50_000  # a run that jams is cut here (counted unfinished); the same cap for both kinds


def _congestion_configs(floor: Floor | None = None):
    ref, size = _on(floor, "setup1", 40)
    return [Config(ref, size, n, physics=p) for n in CONGESTION_AGENTS for p in ("ideal", "physical")]


def _congestion_report(rows, floor: Floor | None = None):
    shown, summary, lines = _shown(floor), [], []
    for n in CONGESTION_AGENTS:
        ideal, _, runs, ideal_unf = _stats(rows, agents=n, physics="ideal")
        phys, phys_std, _, phys_unf = _stats(rows, agents=n, physics="physical")
        bodies = [r for r in rows if r["agents"] == n and r["physics"] == "physical"]
        share = float(np.mean([r["blocked_share"] for r in bodies])) if bodies else float("nan")
        moves = float(np.mean([r["blocked_moves"] for r in bodies])) if bodies else float("nan")
        seconds = sum(r["wall_seconds"] for r in bodies)
        rate = sum(r["iterations"] for r in bodies) / seconds if seconds else float("nan")
        summary.append({"agents": n, "runs": runs, "ideal_mean": round(ideal, 1), "ideal_unfinished": ideal_unf,
                        "physical_mean": round(phys, 1), "physical_std": round(phys_std, 1),
                        "physical_unfinished": phys_unf, "physical_over_ideal": round(phys / ideal, 3),
                        "blocked_share": round(share, 4), "blocked_moves": round(moves, 1),
                        "physical_ticks_per_second": round(rate)})  # fmt: skip
        if shown:
            summary[-1]["paper_mean"] = paper.TABLE1[n][0]
        lines.append([str(n), *([str(paper.TABLE1[n][0])] if shown else []), _fmt(ideal, 0), _fmt(phys, 0),
                      _fmt(phys / ideal, 2), _fmt(share, 3), _fmt(moves, 0), _fmt(rate, 0),
                      f"{phys_unf}/{len(bodies)}"])  # fmt: skip
    md = markdown_table(["agents", *(["paper (Table 1): mean"] if shown else []), "ideal: mean", "physical: mean",
                         "physical / ideal", "blocked share", "blocked moves per run", "physical ticks/s",
                         "physical unfinished"], lines)  # fmt: skip
    md += (f"\n\nPhysical: pymunk discs (the scenario's bodies: diameter 0.4 cells by default). A run still "
           f"foraging after {CONGESTION_CAP:,} ticks is cut there, counted as unfinished, and enters the mean at "
           "the cap. Ticks/s: one run per core while the others run.")  # fmt: skip
    return summary, md


def _congestion_plot(rows, path, floor: Floor | None = None):
    plt = pyplot()
    ns = list(CONGESTION_AGENTS)
    fig, ax = plt.subplots(figsize=(6, 4))
    for physics, marker in (("ideal", "o-"), ("physical", "^-")):
        ax.plot(ns, [_stats(rows, agents=n, physics=physics)[0] for n in ns], marker, label=f"swarm: {physics}")
    if _shown(floor):
        ax.plot(ns, [paper.TABLE1[n][0] for n in ns], "s:", label="paper (Table 1, grid)")
    ax.axhline(CONGESTION_CAP, color="grey", lw=0.8, ls="--", label="cap")
    where = "Setup 1" if floor is None else floor.label
    ax.set(xscale="log", yscale="log", xlabel="agents", ylabel="iterations to forage",
           title=f"{where}: what robot bodies cost")  # fmt: skip
    ax.legend()
    save_figure(fig, path)


# ------------------------------------------------------------------ machinery


EXPERIMENTS: dict[str, Experiment] = {
    "table1": Experiment("table1", "Table 1: setup 1, agents 5..160", 100, _table1_configs,
                         200_000, _table1_report, _table1_plot),
    "table2": Experiment("table2", "Table 2: setup 2, agents 1..8, projected vs experimental", 1000,
                         _table2_configs, 100_000, _table2_report, _table2_plot),
    "table3": Experiment("table3", "Table 3: setup 3, 50 agents, sizes 12..200", 20, _table3_configs,
                         1_000_000, _table3_report, _table3_plot),
    "ants": Experiment("ants", "Section 5.5: c-marking vs the ant model, setup 3 sizes", 10,
                       _ants_configs, 1_000_000, _ants_report, _ants_plot),
    "congestion": Experiment("congestion", "Congestion: setup 1, ideal vs physical bodies, agents 10..160", 10,
                             _congestion_configs, CONGESTION_CAP, _congestion_report, _congestion_plot),
}  # fmt: skip


def plan(name: str, reps: int, seed: int, floor: Floor | None = None) -> list[RunSpec]:
    """Every run of an experiment: its conditions on its floor (the paper's, or `floor`) × the seeds."""
    exp = EXPERIMENTS[name]
    specs = [
        RunSpec(name, c.scenario, c.size, c.agents, c.controller, c.physics, seed + rep, exp.max_iterations)
        for c, rep in cross(exp.configs(floor), range(reps))
    ]
    return sorted(specs, key=expected_work, reverse=True)


def expected_work(spec: RunSpec) -> float:
    """Biggest work first, so the pool is not left waiting on one long run at the end."""
    work = spec.size**2 * (3 if spec.controller == "ant" else 1)
    if spec.physics == "physical":  # bodies cost per agent, and crowds jam
        work *= 10 * spec.agents
    return work


def run_experiment(
    name: str, reps: int | None = None, jobs: int | None = None, seed: int = 0,
    out: Path | None = None, progress: bool = True, scenario: str | None = None,
) -> dict:  # fmt: skip
    """Run one experiment's conditions on the paper's floors, or on `scenario` (a grid floor with a base and
    resources: floors.user_floor), the paper's numbers beside ours only on the paper's own floor."""
    if name not in EXPERIMENTS:
        raise ValueError(f"unknown experiment {name!r}: choose one of {', '.join(EXPERIMENTS)}")
    exp = EXPERIMENTS[name]
    floor = None if scenario is None else user_floor(name, scenario)
    reps = exp.default_reps if reps is None else reps
    if reps < 1:
        raise ValueError("--reps must be at least 1")
    out = Outputs(out, name)
    specs = plan(name, reps, seed, floor)
    physics = sorted({s.physics for s in specs})
    # many short runs go in chunks (less messaging); a few long ones one by one (a live progress bar)
    chunks = max(1, min(16, len(specs) // ((jobs or os.cpu_count() or 1) * 100)))
    rows = batch_run(run_one, specs, jobs=jobs, desc=exp.title.split(":")[0], progress=progress, warm_up=warm_up,
                     warm_args=(physics,), chunksize=chunks)  # fmt: skip
    rows.sort(key=lambda r: (r["size"], r["agents"], r["controller"], r["physics"], r["seed"]))
    out.runs(rows, RUN_FIELDS)
    summary, md = exp.report(rows, floor)
    title = exp.title if floor is None else f"{exp.title.split(':')[0]}'s design on {floor.label}"
    text = (f"# {title}\n\n{reps} runs per configuration, seeds {seed}..{seed + reps - 1}.\n\n"
            f"{floor_note(floor)}{md}\n")  # fmt: skip
    result = out.finish(summary, text)
    exp.plot(rows, out / "plot.png", floor)
    return result


def warm_up(physics: list[str]) -> None:
    """Load (or compile) the engine's kernels for these physics modes, so that no
    run's wall time, and so no ticks/s in a table, includes compiling."""
    from swarm.engines.grid import Engine
    from swarm.scenario import load_scenario

    for mode in physics:
        Engine(load_scenario("setup2").with_overrides(agents=2, physics=mode)).step(2)
