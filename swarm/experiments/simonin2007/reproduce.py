"""`swarm reproduce simonin2007`: every claim of the paper's section 5 beside ours, on the confirmation seeds.

One batch runs Tables 1, 2 and 3 and the ant comparison of section 5.5 through the experiment runner.
A seed is a map (obstacles and resources) whatever the agent count or controller, so the conditions of
one table share their maps seed by seed and their comparisons are paired (Wilcoxon signed-rank, paired
bootstrap).  A run still foraging at its table's cap is censored there: it is counted as unfinished,
its condition's time is the Kaplan-Meier median, and it never enters a mean as if it had finished.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np

from swarm.experiments import protocol as P
from swarm.experiments import report as R
from swarm.experiments import stats as S
from swarm.experiments.runner import Outputs, batch_run
from swarm.experiments.simonin2007 import paper, rules
from swarm.experiments.simonin2007.tables import (
    ANT_SIZES,
    EXPERIMENTS,
    RUN_FIELDS,
    RunSpec,
    expected_work,
    run_one,
    warm_up,
)

# runs per condition: the full report, and --quick (a check that everything runs, not evidence)
REPS = {"table1": 1000, "table2": 5000, "table3": 100, "ants": 100, "rules": 200}  # table 2: the paper's 5000
QUICK_REPS = {"table1": 8, "table2": 40, "table3": 3, "ants": 3, "rules": 3}
TABLES = ("table1", "table2", "table3", "ants")
TITLE = "Simonin, Charpillet & Thierry (2007)"
CONTROLLERS = ("cmarking", "ant")
DESIGN = (
    "A seed is a map, shared by every condition of a table, so comparisons are paired. Intervals are 95% "
    "(bootstrap BCa for means, percentile for ratios; Kaplan-Meier for capped runs)."
)


def plan(reps: dict[str, int]) -> list[RunSpec | tuple]:
    """Every run of the report: each table's conditions × its first n confirmation seeds, and the rules'
    ablation (rules.jobs), biggest first."""
    specs: list[RunSpec | tuple] = [
        RunSpec(name, c.scenario, c.size, c.agents, c.controller, c.physics, seed, EXPERIMENTS[name].max_iterations)
        for name in TABLES
        for c in EXPERIMENTS[name].configs()
        for seed in P.seeds(reps[name], confirm=True)
    ]
    specs += rules.jobs(P.seeds(reps["rules"], confirm=True))
    return sorted(specs, key=_work, reverse=True)


def _work(job: RunSpec | tuple) -> float:
    if isinstance(job, RunSpec):
        return expected_work(job)
    return 100.0**2 * 5 if job[0] == "setup3-100" else 40.0**2  # the literal rule 5 is up to 5x slower


def run_job(job: RunSpec | tuple) -> dict:
    """A table's run (RunSpec) or an ablation's (rules.jobs)."""
    return run_one(job) if isinstance(job, RunSpec) else rules.run_rule(job)


def reproduce(quick: bool = False, jobs: int | None = None, out: Path | None = None, progress: bool = True) -> dict:
    reps = QUICK_REPS if quick else REPS
    out_ = Outputs(out if out is not None else Path("results") / "reproduce" / "simonin2007", "simonin2007")
    specs = plan(reps)
    physics = sorted({s.physics for s in specs if isinstance(s, RunSpec)})
    every = batch_run(run_job, specs, jobs=jobs, desc="simonin2007", progress=progress, warm_up=warm_up,
                      warm_args=(physics,), chunksize=4)  # fmt: skip
    rows = [r for r in every if r["experiment"] != "rules"]
    rows.sort(key=lambda r: (TABLES.index(r["experiment"]), r["size"], r["agents"], r["controller"], r["seed"]))
    ablation = [r for r in every if r["experiment"] == "rules"]
    ablation.sort(key=lambda r: (r["scenario"], r["agents"], r["return_on_trail"], r["at_base"], r["seed"]))
    out_.runs(ablation, rules.FIELDS, file="rules.csv")
    out_.runs(rows, RUN_FIELDS)
    sections = [_table1(rows), _table2(rows), _table3(rows), _ants(rows)]
    claims = [c for _, _, cs in sections for c in cs]
    for name in TABLES:
        EXPERIMENTS[name].plot([r for r in rows if r["experiment"] == name], out_ / f"{name}.png")
    parts = [
        (title, f"{table}\n![{name}]({name}.png)\n") for name, (title, table, _) in zip(TABLES, sections, strict=True)
    ]
    parts += [
        rules.section(ablation),
        ("Known differences", "\n".join(f"- {d}" for d in paper.KNOWN_DIFFERENCES)),
        R.parameters_section(CONTROLLERS),
    ]
    (out_ / "parameters.md").write_text(R.parameters_page(TITLE, CONTROLLERS))
    text = R.report_text(TITLE, DESIGN, claims, parts, reps, quick)
    result = out_.finish([R.claim_row(c) for c in claims], text, file="report.md")
    return result | {"claims": len(claims), "verdicts": R.tally(claims)}


# ----------------------------------------------------------------- sections


def _times(rows: list[dict], **match) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(seeds, iterations, finished) of the matching runs, in seed order."""
    sel = sorted((r for r in rows if all(r[k] == v for k, v in match.items())), key=lambda r: r["seed"])
    return (np.array([r["seed"] for r in sel]), np.array([r["iterations"] for r in sel], float),
            np.array([bool(r["finished"]) for r in sel]))  # fmt: skip


def time_estimate(times: np.ndarray, finished: np.ndarray, seed: int = 0) -> S.Estimate:
    """The mean time when every run finished; the Kaplan-Meier median when some hit the cap."""
    if finished.all():
        return S.mean_ci(times, seed)
    return S.kaplan_meier_median(times, finished)


def _cell(e: S.Estimate, finished: np.ndarray) -> str:
    capped = int((~finished).sum())
    label = "" if e.what == "mean" else " (KM median)"
    return f"{e.text(3)}{label}" + (f", {capped}/{len(finished)} capped" if capped else "")


def _table1(rows: list[dict]):
    lines, claims = [], []
    for n, (p_mean, p_std) in paper.TABLE1.items():
        _, t, done = _times(rows, experiment="table1", agents=n)
        lines.append([str(n), _cell(time_estimate(t, done), done), S.number(t.std(), 4), str(p_mean), str(p_std)])
    agents = list(paper.TABLE1)
    for n, m in itertools.pairwise(agents):
        _, a, _ = _times(rows, experiment="table1", agents=n)
        _, b, _ = _times(rows, experiment="table1", agents=m)
        est, test = S.ratio_of_means(b, a, paired=True, null=0.5)
        paper_ratio = paper.TABLE1[m][0] / paper.TABLE1[n][0]
        claims.append(P.Claim(f"setup 1: doubling {n} to {m} agents at least halves the time (T({m})/T({n}) <= 0.5)",
                              f"{paper_ratio:.2f}", est.text(3), test, expected=-1))  # fmt: skip
    table = R.markdown_table(["agents", "ours: iterations (95% CI)", "ours: std", "paper: mean", "paper: std"], lines)
    return "Table 1: setup 1 (40x40, 30% obstacles, 20 resources), agents 5 to 160", table, claims


def _table2(rows: list[dict]):
    _, t1, _ = _times(rows, experiment="table2", agents=1)
    lines, claims, savings, ns = [], [], [], []
    for n, p_exp in paper.TABLE2.items():
        _, t, done = _times(rows, experiment="table2", agents=n)
        saving = t1 / n - t  # per seed: projected (the lone agent's time on that map, over n) minus experimental
        est = S.mean_ci(saving)
        savings.append(saving)
        ns.append(np.full(len(saving), n))
        lines.append([str(n), _cell(time_estimate(t, done), done), est.text(3) if n > 1 else "–", f"{p_exp}",
                      f"{paper.TABLE2[1] / n - p_exp:.1f}" if n > 1 else "–"])  # fmt: skip
    _, t2, _ = _times(rows, experiment="table2", agents=2)
    claims.append(P.Claim("setup 2: 1 to 2 agents is super-linear (T(1)/2 - T(2) > 0)",
                          f"{paper.TABLE2[1] / 2 - paper.TABLE2[2]:+.1f}", S.mean_ci(t1 / 2 - t2).text(3),
                          S.wilcoxon_paired(t1 / 2, t2)))  # fmt: skip
    claims.append(P.Claim("setup 2: the saving T(1)/n - T(n) falls as n grows from 2 to 8",
                          "+23.7 to -12.4", "see the table", S.spearman(np.concatenate(ns[1:]),
                          np.concatenate(savings[1:])), expected=-1))  # fmt: skip
    table = R.markdown_table(["agents", "ours: iterations (95% CI)", "ours: T(1)/n - T(n) (95% CI)", "paper: mean",
                 "paper: projected - experimental"], lines)  # fmt: skip
    return "Table 2: setup 2 (20x20, 5% obstacles, 2 resources), super-linearity", table, claims


def _table3(rows: list[dict]):
    lines, claims, prev = [], [], None
    sizes = list(paper.TABLE3)
    for size, p_mean in paper.TABLE3.items():
        _, t, done = _times(rows, experiment="table3", size=size)
        r = "–"
        if prev is not None:
            r = S.ratio_of_means(t, prev, paired=False, null=2.0)[0].text(3)
        p_r = f"{p_mean / paper.TABLE3[sizes[sizes.index(size) - 1]]:.2f}" if prev is not None else "–"
        lines.append([f"{size}x{size}", _cell(time_estimate(t, done), done), r, f"{p_mean}", p_r])
        prev = t
    _, big, _ = _times(rows, experiment="table3", size=200)
    _, mid, _ = _times(rows, experiment="table3", size=100)
    est, test = S.ratio_of_means(big, mid, paired=False, null=2.0)
    claims.append(P.Claim("setup 3: beyond 100x100, R (the time ratio per quadrupled area) rises above 2",
                          f"{paper.TABLE3[200] / paper.TABLE3[100]:.2f}", est.text(3), test))  # fmt: skip
    table = R.markdown_table(
        ["size", "ours: iterations (95% CI)", "ours: R (95% CI)", "paper: mean", "paper: R"], lines
    )
    return "Table 3: setup 3 (5% obstacles, 20 resources, 50 agents), sizes 12 to 200", table, claims


def _ants(rows: list[dict]):
    lines, claims, sizes, gaps = [], [], [], []
    for size in ANT_SIZES:
        s_cm, cm, cm_done = _times(rows, experiment="ants", size=size, controller="cmarking")
        s_ant, ant, ant_done = _times(rows, experiment="ants", size=size, controller="ant")
        assert np.array_equal(s_cm, s_ant)  # the same maps, seed by seed
        gap, _ = S.ratio_of_means(cm, ant, paired=True)
        percent = f"{100 * (1 - gap.value):.0f}% [{100 * (1 - gap.high):.0f}, {100 * (1 - gap.low):.0f}]"
        lines.append([f"{size}x{size}", _cell(time_estimate(cm, cm_done), cm_done),
                      _cell(time_estimate(ant, ant_done), ant_done), percent])  # fmt: skip
        claims.append(P.Claim(f"section 5.5, {size}x{size}: c-marking forages faster than ants", "yes (Fig. 9)",
                              f"gap {100 * (1 - gap.value):.0f}%", S.wilcoxon_paired(ant, cm)))  # fmt: skip
        sizes.append(np.full(len(cm), size))
        gaps.append(1 - cm / ant)
    largest = paper.ANT_GAP_PERCENT[-1]
    est, test = S.ratio_of_means(cm, ant, paired=True, null=1 - largest / 100)
    claims.append(P.Claim(f"section 5.5: at the largest size ({ANT_SIZES[-1]}x{ANT_SIZES[-1]}) the gap has shrunk "
                          f"to the paper's last value", f"{largest}%",
                          f"{100 * (1 - est.value):.0f}% [{100 * (1 - est.high):.0f}, {100 * (1 - est.low):.0f}]",
                          test, expected=0))  # fmt: skip
    claims.append(P.Claim("section 5.5: the gap 1 - c-marking/ants shrinks as the environment grows",
                          " -> ".join(f"{g}%" for g in paper.ANT_GAP_PERCENT), "see the table",
                          S.spearman(np.concatenate(sizes), np.concatenate(gaps)), expected=-1))  # fmt: skip
    table = R.markdown_table(
        ["size", "c-marking: iterations (95% CI)", "ants: iterations (95% CI)", "gap (95% CI)"], lines
    )
    return "Section 5.5: c-marking against the ant model (setup 3, 50 agents)", table, claims
