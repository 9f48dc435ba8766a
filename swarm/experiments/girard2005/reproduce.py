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

import math
from pathlib import Path

import numpy as np

from swarm.experiments import protocol as P
from swarm.experiments import report as R
from swarm.experiments import stats as S
from swarm.experiments.girard2005 import bg, paper
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


# ----------------------------------------------------------------- helpers


def _select(rows: list[dict], experiment: str, condition) -> list[dict]:
    """One condition's runs in run order (run k of every condition shares map k and seed 10000 + k)."""
    return sorted((r for r in rows if r["experiment"] == experiment and r["condition"] == condition),
                  key=lambda r: r["run"])  # fmt: skip


def _share(k: int, n: int) -> str:
    return f"{k}/{n}: " + S.proportion_ci(k, n).text(2)


def _vs_paper(k: int, n: int, paper_k: int, paper_n: int) -> str:
    """Our k of n against the paper's (independent samples): Fisher's exact p."""
    return f"{S.fisher(k, n, paper_k, paper_n).p:.2f}" if n else "n/a"


def _km_text(times: np.ndarray, finished: np.ndarray, cap: float) -> str:
    """The Kaplan-Meier median, or "> cap" where more than half the runs outlasted it."""
    e = S.kaplan_meier_median(times, finished)
    return e.text(4) if not math.isnan(e.value) else f"> {S.number(cap, 4)} (over half censored)"


# ----------------------------------------------------------------- sections


def _survival(rows: list[dict], quick: bool):
    cap = QUICK_SECONDS if quick else paper.CAP_SECONDS
    t, done = {}, {}
    lines = []
    for c in ("A", "B"):
        sel = _select(rows, "bg-survival", c)
        t[c] = np.array([r["survival_seconds"] for r in sel], float)
        done[c] = np.array([bool(r["died"]) for r in sel])
        median, low, high = paper.PAPER_SURVIVAL[c]
        four_h = paper.CAP_SECONDS  # the paper's own limit, whatever this run's cap
        capped = f"{S.number(four_h, 5)} (≥ 5 of 10 past it)" if median > four_h else S.number(median, 5)
        lines.append([c, f"{len(t[c])} ({paper.SURVIVAL_TESTS})", _km_text(t[c], done[c], cap),
                      _share(int((~done[c]).sum()), len(t[c])), f"{t[c].min():,.0f} : {t[c].max():,.0f}",
                      S.restricted_mean_ci(t[c], done[c], cap).text(4), f"{median:,} ({low:,} : {high:,})",
                      capped])  # fmt: skip
    mw = S.mann_whitney(t["A"], t["B"])
    lr = S.logrank(t["A"], done["A"], t["B"], done["B"])
    paper_text = "medians 14,431.5 / 4,908 s; U = 15, p < 0.01 (n 10 + 10)"
    ours = f"KM medians {_km_text(t['A'], done['A'], cap)} / {_km_text(t['B'], done['B'], cap)} s"
    alive = int((~done["A"]).sum())
    claims = [
        P.Claim("exp. 1: A (taxon + map) survives longer than B (taxon only): the paper's U test", paper_text, ours,
                mw),
        P.Claim("exp. 1: A survives longer than B, runs alive at the cap censored (log-rank)", paper_text,
                f"restricted means to {S.number(cap, 4)} s: " + " / ".join(
                    S.restricted_mean_ci(t[c], done[c], cap).text(4) for c in ("A", "B")), lr),
        P.Claim(f"exp. 1: A's runs alive at the cap ({S.number(cap, 4)} s); no difference from the paper's 5/10 "
                "(its least) expected", "≥ 5/10 (median 14,431.5 s > 4 h)", _share(alive, len(t["A"])),
                S.fisher(alive, len(t["A"]), 5, paper.SURVIVAL_TESTS), expected=0),
    ]  # fmt: skip
    table = R.markdown_table(["condition", "runs (paper)", "ours: KM median (s)", "ours: alive at cap",
                              "ours: range (s)", "ours: restricted mean (s)", "paper: median (range)",
                              "paper, capped at 4 h: median"], lines)  # fmt: skip
    note = (f"\nMann-Whitney U = {mw.statistic:.1f}, p = {mw.p:.3g}; log-rank p = {lr.p:.3g}.  The paper's A "
            "median (14,431.5 s) and maximum (17,274 s) exceed its own 4 h limit (14,400 s): at least five of its "
            "ten A runs went past 14,431.5 s, so, capped at 4 h as ours are, its A median is the cap itself and "
            "its A range 2,531 : 14,400.  Our runs stop at the cap; its U test on our capped times counts every run "
            "alive at the cap as a tie.\n")  # fmt: skip
    return "Experiment 1: survival with (A) and without (B) the map (Table 1)", table + note, claims


def _counts(sel: list[dict], option: str, field: str = "chose") -> np.ndarray:
    return np.array([r[field] == option for r in sel])


def _choice(rows: list[dict]):
    lines, ep1 = [], {}
    for w, (p1, p2) in paper.PAPER_CHOICE.items():
        sel = _select(rows, "bg-choice", w)
        ep1[w] = _counts(sel, "Ep1")
        n1, n2 = int(ep1[w].sum()), int(_counts(sel, "Ep2").sum())
        lines.append([f"{w:g}", f"{len(sel)} ({paper.CHOICE_TESTS})", str(n1), str(n2), str(len(sel) - n1 - n2),
                      _share(n1, len(sel)), f"{p1} : {p2}", _vs_paper(n1, len(sel), p1, p1 + p2)])  # fmt: skip
    control = _select(rows, "bg-choice", bg.CHOICE_CONTROL)
    c1 = int(_counts(control, "Ep1").sum())
    lines.append([f"{bg.CHOICE_CONTROL} (W_plan 0.65)", f"{len(control)} (10)", str(c1),
                  "–", str(len(control) - c1), _share(c1, len(control)), "10 : 0 (\"directly to Ep1\")",
                  _vs_paper(c1, len(control), 10, 10)])  # fmt: skip
    ws = list(paper.PAPER_CHOICE)
    claims = [
        P.Claim("exp. 2.1: the lower W_plan, the fewer tests go to the mapped Ep1 (W_plan 0.65 against 0.45, "
                "the same maps)", "13/15 vs 2/15", f"{int(ep1[ws[0]].sum())}/{len(ep1[ws[0]])} vs "
                f"{int(ep1[ws[-1]].sum())}/{len(ep1[ws[-1]])}", S.mcnemar(ep1[ws[0]], ep1[ws[-1]])),
        P.Claim("exp. 2.1: Ep1's share differs as W_plan falls (0.65, 0.55, 0.45; the same maps test by test)",
                "13 → 7 → 2 of 15", " → ".join(str(int(ep1[w].sum())) for w in ws) + f" of {len(ep1[ws[0]])}",
                S.cochrans_q([ep1[w] for w in ws])),
        P.Claim("exp. 2.1 control: without Ep2 the animat goes directly to Ep1; no difference from the paper's "
                "10/10 expected", "10/10 (\"repeatable\")", _share(c1, len(control)),
                S.fisher(c1, len(control), 10, 10), expected=0),
    ]  # fmt: skip
    table = R.markdown_table(["W_plan (W_taxon 0.55)", "tests (paper)", "Ep1", "Ep2", "neither", "ours: Ep1 share",
                              "paper: Ep1 : Ep2", "ours vs paper: Fisher p"], lines)  # fmt: skip
    return "Experiment 2.1: a new resource, planning against taxon (Table 2)", table, claims


def _forget(rows: list[dict]):
    sel = _select(rows, "bg-forget", "Ep2 gone")
    direct = bg.direct_seconds("bg-exp2")
    reached = np.array([r["chose"] == "Ep1" and r["seconds"] is not None for r in sel])
    t = np.array([r["seconds"] if ok else bg.TEST_SECONDS for r, ok in zip(sel, reached, strict=True)], float)
    forget = t - direct
    km = S.kaplan_meier_median(t, reached)
    km_text = (f"{S.number(km.value - direct, 3)} [{S.number(km.low - direct, 3)}, {S.number(km.high - direct, 3)}]"
               if not math.isnan(km.value) else f"> {bg.TEST_SECONDS - direct:.0f} (over half censored)")  # fmt: skip
    rm = S.restricted_mean_ci(t, reached, bg.TEST_SECONDS)
    rm_text = f"{rm.value - direct:.0f} [{rm.low - direct:.0f}, {rm.high - direct:.0f}]"
    within = int((reached & (forget <= paper.PAPER_FORGET[2])).sum())
    pm, ps, px = paper.PAPER_FORGET
    lines = [[f"{len(sel)} ({paper.FORGET_TESTS})", _share(int(reached.sum()), len(sel)), km_text, rm_text,
              _share(within, len(sel)), f"{direct:.0f}", f"{pm:.0f} (sd {ps:.0f}), max {px:.0f}",
              f"{paper.FORGET_TESTS}/{paper.FORGET_TESTS}", f"{paper.FORGET_DIRECT_SECONDS:.0f}"]]  # fmt: skip
    claims = [
        P.Claim("exp. 2.2: the animat forgets the exhausted Ep2 and reloads at Ep1 within the paper's longest "
                "forgetting (300 s); no difference from the paper's 15/15 expected", "15/15",
                _share(within, len(sel)), S.fisher(within, len(sel), paper.FORGET_TESTS, paper.FORGET_TESTS),
                expected=0),
        P.Claim("exp. 2.2: the time to forget (to Ep1 less the direct path), tests that never reached Ep1 "
                f"censored at {bg.TEST_SECONDS:.0f} s", f"mean {pm:.0f} s (sd {ps:.0f})",
                f"restricted mean {rm_text} s; KM median {km_text} s", None),
    ]  # fmt: skip
    table = R.markdown_table(["tests (paper)", "ours: reached Ep1", "ours: KM median to forget (s)",
                              f"ours: restricted mean to forget, to {bg.TEST_SECONDS:.0f} s (s)",
                              "ours: forgot within 300 s", "ours: direct path (s)", "paper: time to forget (s)",
                              "paper: reached Ep1", "paper: direct path (s)"], lines)  # fmt: skip
    note = (
        "\nA test that has not reloaded at Ep1 when it ends is censored there, not dropped: the restricted mean "
        "is the area under the Kaplan-Meier curve of the time to reload, less the direct path.\n"
    )
    return "Experiment 2.2: forgetting an exhausted resource", table + note, claims


def _fear(rows: list[dict]):
    lines, ep1, ep2 = [], {}, {}
    for ep in (*bg.FEAR_EP, *bg.FEAR_CONTROL.values()):
        sel = _select(rows, "bg-fear", ep)
        ep1[ep], ep2[ep] = _counts(sel, "Ep1"), _counts(sel, "Ep2")
        n1, n2 = int(ep1[ep].sum()), int(ep2[ep].sum())
        died = sum(bool(r["died"]) for r in sel if r["chose"] not in ("Ep1", "Ep2"))
        p1, p2 = paper.PAPER_FEAR.get(ep, (None, None))
        lines.append([str(ep), f"{len(sel)} ({paper.FEAR_TESTS if p1 is not None else '–'})", str(n1), str(n2),
                      f"{len(sel) - n1 - n2}" + (f" ({died} died)" if died else ""), _share(n1, len(sel)),
                      f"{p1} : {p2}" if p1 is not None else "Ep1 \"systematically\"",
                      _vs_paper(n1, n1 + n2, p1, p1 + p2) if p1 is not None else "–"])  # fmt: skip
    strong, moderate = bg.FEAR_EP
    control = bg.FEAR_CONTROL[moderate]
    s1, m1 = int(ep1[strong].sum()), int(ep1[moderate].sum())
    s_n, m_n = s1 + int(ep2[strong].sum()), m1 + int(ep2[moderate].sum())
    claims = [
        P.Claim("exp. 3.1: a strong lack of Ep (0.1) takes the animat past the danger to Ep1 more often than a "
                "moderate one (0.5): the paper's Fisher test on (Ep1, Ep2)", "13/20 vs 2/20, p < 0.01",
                f"{s1}/{s_n} vs {m1}/{m_n}", S.fisher(s1, s_n, m1, m_n)),
        P.Claim("exp. 3.1: the same, paired on the maps and seeds (McNemar on Ep1, 'neither' not Ep1)",
                "13/20 vs 2/20", f"{s1}/{len(ep1[strong])} vs {m1}/{len(ep1[moderate])}",
                S.mcnemar(ep1[strong], ep1[moderate])),
        P.Claim("exp. 3.1: at Ep 0.5 the dangerous area turns the animat from the closest Ep1 (without it "
                "against with it; other maps, so Fisher)", "\"systematically\" Ep1 vs 2/20",
                f"{int(ep1[control].sum())}/{len(ep1[control])} vs {m1}/{len(ep1[moderate])}",
                S.fisher(int(ep1[control].sum()), len(ep1[control]), m1, len(ep1[moderate]))),
    ]  # fmt: skip
    table = R.markdown_table(["Ep at start (F = 0.2)", "tests (paper)", "Ep1", "Ep2", "neither", "ours: Ep1 share",
                              "paper: Ep1 : Ep2", "ours vs paper: Fisher p on (Ep1, Ep2)"], lines)  # fmt: skip
    note = (
        '\nThe "no DA" rows are the paper\'s control, given in words only: the dangerous area absent from the '
        "floor while mapping and in the test, F = 0.2 still, the same seeds.  Died: E ran out before any reload "
        "(the dangerous area drains E).\n"
    )
    return "Experiment 3.1: fear against the need for Ep (Table 3)", table + note, claims


def _tmaze(rows: list[dict]):
    lines, left, entered = [], {}, {}
    for ratio, (p_left, p_right) in paper.PAPER_TMAZE.items():
        sel = _select(rows, "bg-tmaze", ratio)
        left[ratio], right = _counts(sel, "left", "branch"), _counts(sel, "right", "branch")
        entered[ratio] = left[ratio] | right
        nl, nr = int(left[ratio].sum()), int(right.sum())
        lines.append([f"{ratio:g}", f"{len(sel)} ({paper.TMAZE_TESTS})", str(nl), str(nr), str(len(sel) - nl - nr),
                      _share(nr, nl + nr), f"{p_left} : {p_right}",
                      _vs_paper(nr, nl + nr, p_right, p_left + p_right)])  # fmt: skip
    claims = []
    for ratio in (1.0, 1.5):
        nl, n = int(left[ratio].sum()), int(entered[ratio].sum())
        p_left, p_right = paper.PAPER_TMAZE[ratio]
        claims.append(P.Claim(f"exp. 3.2, ratio {ratio:g}: the right branch (E and Ep) is entered first more often "
                              "than the left (Ep only)", f"{p_right}/15", _share(n - nl, n),
                              S.binomial(n - nl, n)))  # fmt: skip
    ratios = list(paper.PAPER_TMAZE)
    x = np.concatenate([np.full(int(entered[r].sum()), r) for r in ratios])
    y = np.concatenate([left[r][entered[r]] for r in ratios])
    claims.append(P.Claim("exp. 3.2: the longer the right branch, the more often the left is entered first",
                          "3 → 4 → 8 of 15",
                          " → ".join(f"{int(left[r].sum())}/{int(entered[r].sum())}" for r in ratios),
                          S.spearman(x, y)))  # fmt: skip
    table = R.markdown_table(["right / left length", "tests (paper)", "left", "right", "neither",
                              "ours: right share of first choices", "paper: left : right",
                              "ours vs paper: Fisher p"], lines)  # fmt: skip
    note = (
        "\nEach ratio is its own floor and maps, so the trend's test (Spearman over the tests that entered a "
        "branch) treats them as independent.\n"
    )
    return "Experiment 3.2: the T-maze, first branch entered (Table 4)", table + note, claims


# ------------------------------------------------------------------ plot


def _plot(rows: list[dict], path: Path) -> None:
    """Survival curves (A, B) and the three choice tables' shares, ours with intervals, the paper's as marks."""
    from scipy.stats import ecdf

    from swarm.core.plots import pyplot, save_figure

    plt = pyplot()
    fig, axes = plt.subplots(1, 4, figsize=(16, 3.8))
    ax = axes[0]
    for c, colour in (("A", "C0"), ("B", "C1")):
        sel = _select(rows, "bg-survival", c)
        t = np.array([r["survival_seconds"] for r in sel], float) / 3600
        sf = ecdf(S._censored(t, [bool(r["died"]) for r in sel])).sf
        ax.step(np.concatenate([[0], sf.quantiles]), np.concatenate([[1], sf.probabilities]), where="post",
                color=colour, label=f"{c} (ours)")  # fmt: skip
        ax.axvline(paper.PAPER_SURVIVAL[c][0] / 3600, color=colour, ls="--", label=f"{c}: the paper's median")
    ax.set(xlabel="hours", ylabel="share alive", title="exp. 1: survival (Kaplan-Meier)")
    ax.legend(fontsize=7)
    panels = [
        ("bg-choice", paper.PAPER_CHOICE, "Ep1", "chose", "W_plan", "exp. 2.1: Ep1 share", 0),
        ("bg-fear", paper.PAPER_FEAR, "Ep1", "chose", "Ep at start", "exp. 3.1: Ep1 share", 0),
        ("bg-tmaze", paper.PAPER_TMAZE, "right", "branch", "right / left length", "exp. 3.2: right share", 1),
    ]
    for ax, (experiment, table, option, field, xlabel, title, column) in zip(axes[1:], panels, strict=True):
        for k, (cond, counts) in enumerate(table.items()):
            sel = _select(rows, experiment, cond)
            e = S.proportion_ci(int(_counts(sel, option, field).sum()), len(sel))
            ax.errorbar(k, e.value, yerr=[[e.value - e.low], [e.high - e.value]], fmt="o", color="C0",
                        label="ours (95% CI)" if k == 0 else None)  # fmt: skip
            ax.plot(k, counts[column] / sum(counts), "rx", ms=9, label="the paper" if k == 0 else None)
        ax.set_xticks(range(len(table)), [f"{c:g}" for c in table])
        ax.set(xlabel=xlabel, ylim=(-0.05, 1.05), title=title)
        ax.legend(fontsize=7)
    save_figure(fig, path)  # fmt: skip
