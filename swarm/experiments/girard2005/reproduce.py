"""`swarm reproduce girard2005`: experiments 1, 2.1, 2.2, 3.1 and 3.2 of Girard et al. (2005) on the
confirmation seeds, every claim of the paper beside ours.

The runs are the experiments' own (`bg.run_survival`, `bg.build_map`, `bg.run_test`), with their scenarios
and settings unchanged.  Run k of an experiment has seed 10000 + k; its mapping run (experiments 2 and 3)
has seed 15000 + k, so a test's noise is not its mapping run's replayed.  Test k of every condition of an
experiment loads map k and has seed 10000 + k: those conditions are compared pairwise (McNemar).  The two
animats of experiment 1 share only the seed, not a map (A maps as it lives), so they are independent
samples.  A survival run alive at 4 h, and a forgetting test that has not reloaded at Ep1 by its end,
are censored there (Kaplan-Meier, log-rank, restricted means), never dropped nor averaged in as finished.
"""

from __future__ import annotations

from pathlib import Path

from swarm.experiments import protocol as P
from swarm.experiments import report as R
from swarm.experiments.girard2005 import bg, paper, sections
from swarm.experiments.girard2005.mapping import MappingParams
from swarm.experiments.runner import Outputs, batch_run

TITLE = "Girard, Filliat, Meyer, Berthoz & Guillot (2005)"
PROTOCOL = (MappingParams,)  # the experiments' own declared numbers: how the maps of experiments 2 and 3 are made
CONTROLLERS = ("bg",)
# tests (runs) per condition: the paper's n everywhere (the full report costs about 11 min on 2 cores); --quick
# checks that everything runs and is not evidence
REPS = {"bg-survival": paper.SURVIVAL_TESTS, "bg-choice": paper.CHOICE_TESTS, "bg-forget": paper.FORGET_TESTS,
        "bg-fear": paper.FEAR_TESTS, "bg-tmaze": paper.TMAZE_TESTS}  # fmt: skip
QUICK_REPS = {name: 3 for name in REPS}
# a quick run also shortens the simulated time: survival and mapping runs end at 20 min
QUICK_SECONDS = 1200.0
MAP_SEED_OFFSET = 5000  # mapping run k: confirmation seed 15000 + k
PAPER_N = {"bg-survival": "10 per condition", "bg-choice": "15 per W_plan, 10 controls", "bg-forget": "15",
           "bg-fear": "20 per Ep level", "bg-tmaze": "15 per ratio"}  # fmt: skip
FIELDS = ["experiment", "condition", "run", "seed", "map", "map_seed", "survival_seconds", "died", "chose", "branch",
          "seconds", "distance", "nodes", "reload_e_seconds", "reload_ep_seconds", "idle_acts",
          "wall_seconds"]  # fmt: skip
MAP_FIELDS = ["experiment", "scenario", "index", "seed", "mapped_seconds", "nodes", "visited"]
DESIGN = (
    "Run k of each experiment has seed 10000 + k; the mapping run whose map test k loads (experiments 2 and 3) "
    "has seed 15000 + k.  Conditions of one experiment share maps and seeds test by test, so their comparisons "
    "are paired (McNemar); the paper's own test (Mann-Whitney, Fisher) stands beside ours.  Survival runs alive "
    "at 4 h and forgetting tests that never reached Ep1 are censored (Kaplan-Meier, log-rank, restricted means). "
    "Intervals are 95% (Wilson for shares, bootstrap for means, Kaplan-Meier for medians)."
)
KNOWN_DIFFERENCES = (
    "Every dimension of the floors is ours (the paper's figures are not available); so is every parameter the "
    "paper leaves open (docs/bg.md, Parameters).",
    "Every experiment runs one declared parameter set (agents/controllers/bg/params.py); an experiment changes "
    "only what the paper varies (the saliences' variant, W_plan, F's condition, the start levels of E and Ep).",
    'How the paper\'s "previously built map" was made is not said: ours comes from a mapping run that explores '
    "without planning (W_plan 0) for at least 30 min, then until the animat's own map holds every kind of "
    "resource on the floor, at most 2 h; it starts at E = Ep = 0.5, with E lasting 4 h and danger costing "
    "nothing, so that the mapping animat lives to map.",
    "The 3.1 control (the paper's words only): the dangerous area is absent from the floor, in the mapping run "
    "and in the test; F stays 0.2.  Its maps are made on that other floor, so its tests are compared with "
    "the others as independent samples (Fisher).",
    "During an act the loops alone stop the animat (eq. 10's trans-subthalamic pathway), as in the paper; "
    "`swarm experiment bg-ablations` runs it with the wheels also set to zero during an act, a rule of ours.",
    "The ventral read-out counts a channel released up to 1.6 times its resting output (a threshold of ours) "
    "and drops a direction whose vector sum is shorter than a tenth of its weights; the dorsal read-out starts "
    "an act above a disinhibition of 0.9 and keeps the incumbent while it stays above 0 (ours); the cortical "
    "feedback counts above its resting level only (bg-ablations: the feedback as printed).",
    "Odometry and compass errors are drawn independently each tick, unbiased; bg-ablations runs them biased "
    "(drawn once per animat and run), so that the odometric position drifts.",
    'A test of experiments 2 and 3 ends at 900 s ("none" if it has not reloaded Ep); the paper\'s ran until '
    "ReloadEp.  Forgetting's direct path is ours (A* on our floor), the paper's 46 s.",
    "Experiment 3.2's first branch is where the animat first crosses the T's bar north of the stem's walls.",
)


# ------------------------------------------------------------------ runs


def plan(reps: dict[str, int], quick: bool) -> list[tuple]:
    """The runs that need no map first: survival runs and mapping runs, longest first ((kind, experiment, job))."""
    survival_cap = int(QUICK_SECONDS / 0.25) if quick else None
    jobs = [("survival", "bg-survival", (c, k, seed, {}, survival_cap))
            for c in ("A", "B") for k, seed in enumerate(P.seeds(reps["bg-survival"], confirm=True))]  # fmt: skip
    seconds = QUICK_SECONDS if quick else bg.MAPPING_SECONDS
    for experiment in ("bg-choice", "bg-forget", "bg-fear", "bg-tmaze"):
        for name, (floor, absent) in bg.mapped_floors(experiment, bg.check_floors(experiment, None, None, {})).items():
            map_seeds = P.seeds(reps[experiment], confirm=True, offset=MAP_SEED_OFFSET)
            jobs += [("map", experiment, (name, k, seed, floor, absent, {}, bg.MAPPING, seconds))
                     for k, seed in enumerate(map_seeds)]  # fmt: skip
    work = {"A": 10.0, "B": 3.0, "bg-forget": 3.0, "bg-fear": 2.0}
    return sorted(jobs, key=lambda j: work.get(j[2][0] if j[0] == "survival" else j[1], 1.0), reverse=True)


def run_job(job: tuple) -> dict:
    """A survival run or a mapping run, tagged with its experiment."""
    kind, experiment, payload = job
    row = bg.run_survival(payload) if kind == "survival" else bg.build_map_job(payload)
    return {"kind": kind, "experiment": experiment, "seed": payload[2], **row}


def reproduce(quick: bool = False, jobs: int | None = None, out: Path | None = None, progress: bool = True) -> dict:
    reps = QUICK_REPS if quick else REPS
    out_ = Outputs(out if out is not None else Path("results") / "reproduce" / "girard2005", "girard2005")
    first = batch_run(run_job, plan(reps, quick), jobs=jobs, desc="girard2005 survival, maps", progress=progress)
    survival = sorted((r for r in first if r["kind"] == "survival"), key=lambda r: (r["condition"], r["run"]))
    maps = sorted((r for r in first if r["kind"] == "map"), key=lambda r: (r["experiment"], r["scenario"], r["index"]))
    out_.runs([_map_row(m) for m in maps], MAP_FIELDS, file="maps.csv")
    tests = []
    for experiment in ("bg-choice", "bg-forget", "bg-fear", "bg-tmaze"):
        made: dict[str, list[dict]] = {}
        for m in (m for m in maps if m["experiment"] == experiment):
            made.setdefault(m["scenario"], []).append(m["data"])
        tests += bg.test_jobs(experiment, reps[experiment], P.CONFIRMATION_SEEDS.start, made)
    rows = batch_run(bg.run_test, tests, jobs=jobs, desc="girard2005 tests", progress=progress)
    for r in rows:
        r["map_seed"] = P.CONFIRMATION_SEEDS.start + MAP_SEED_OFFSET + r["map"]
    rows = [{**r, "experiment": "bg-survival"} for r in survival] + rows
    out_.runs(rows, FIELDS)
    sections = [_survival(rows, quick), _choice(rows), _forget(rows), _fear(rows), _tmaze(rows)]
    claims = [c for _, _, cs in sections for c in cs]
    _plot(rows, out_ / "girard2005.png")
    parts = [(title, table) for title, table, _ in sections]
    parts.append(("Known differences", "\n".join(f"- {line}" for line in KNOWN_DIFFERENCES) + "\n"))
    parts.append(R.parameters_section(CONTROLLERS, PROTOCOL))
    (out_ / "parameters.md").write_text(R.parameters_page(TITLE, CONTROLLERS, PROTOCOL))
    design = DESIGN + (f"  This quick run also ends survival and mapping runs at {QUICK_SECONDS / 60:.0f} min "
                       "(the paper: 4 h and a full mapping phase)." if quick else "")  # fmt: skip
    text = R.report_text(TITLE, design, claims, parts, reps, quick)
    text += "\n![survival, choices and forgetting](girard2005.png)\n"
    result = out_.finish([R.claim_row(c) for c in claims], text, file="report.md")
    return result | {"claims": len(claims), "verdicts": R.tally(claims)}


def _map_row(m: dict) -> dict:
    d = m["data"]
    return {"experiment": m["experiment"], "scenario": m["scenario"], "index": m["index"], "seed": m["seed"],
            "mapped_seconds": d["mapped_seconds"], "nodes": len(d["map"]["nodes"]),
            "visited": " ".join(d["visited"])}  # fmt: skip


# ----------------------------------------------------------------- sections (girard2005/sections.py)


def _survival(rows: list[dict], quick: bool) -> tuple[str, str, list[P.Claim]]:
    return sections.survival(rows, QUICK_SECONDS if quick else paper.CAP_SECONDS)


def _forget(rows: list[dict]) -> tuple[str, str, list[P.Claim]]:
    return sections.forget(rows, bg.direct_seconds(bg.SCENARIO["bg-forget"]))


_choice, _fear, _tmaze = sections.choice, sections.fear, sections.tmaze


def _plot(rows: list[dict], path: Path) -> None:
    """Survival curves (A, B) and the three choice tables' shares, ours with intervals, the paper's as marks."""
    from swarm.core.plots import pyplot, save_figure

    plt = pyplot()
    fig, axes = plt.subplots(1, 4, figsize=(16, 3.8))
    sections.survival_panel(axes[0], rows)
    for ax, experiment in zip(axes[1:], ("bg-choice", "bg-fear", "bg-tmaze"), strict=True):
        sections.shares_panel(ax, experiment, rows, list(sections.SHARES[experiment][0]))
    save_figure(fig, path)
