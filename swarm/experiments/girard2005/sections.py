"""The tables of Girard et al. (2005)'s experiments, one section per experiment: its markdown table, the
paper beside ours with intervals, and the paper's claims with our tests of them.  `swarm reproduce girard2005`
and `swarm experiment bg-*` render the same sections, so a standalone table and the report read alike.

A survival run alive at its cap, and a forgetting test that has not reloaded at Ep1 by its end, are censored
there (Kaplan-Meier, log-rank, restricted means), never dropped nor averaged in as finished.  Conditions that
share maps and seeds test by test are compared pairwise (McNemar, Cochran's Q); ours against the paper's
counts, as independent samples (Fisher).
"""

from __future__ import annotations

import math

import numpy as np

from swarm.experiments import protocol as P
from swarm.experiments import report as R
from swarm.experiments import stats as S
from swarm.experiments.girard2005 import bg, paper


def select(rows: list[dict], experiment: str, condition) -> list[dict]:
    """One condition's runs in run order (run k of every condition shares map k and its seed)."""
    return sorted((r for r in rows if r["experiment"] == experiment and r["condition"] == condition),
                  key=lambda r: r["run"])  # fmt: skip


def share(k: int, n: int) -> str:
    return f"{k}/{n}: " + S.proportion_ci(k, n).text(2)


def _vs_paper(k: int, n: int, paper_k: int, paper_n: int) -> str:
    """Our k of n against the paper's (independent samples): Fisher's exact p."""
    return f"{S.fisher(k, n, paper_k, paper_n).p:.2f}" if n else "n/a"


def _km_text(times: np.ndarray, finished: np.ndarray, cap: float) -> str:
    """The Kaplan-Meier median, or "> cap" where more than half the runs outlasted it."""
    e = S.kaplan_meier_median(times, finished)
    return e.text(4) if not math.isnan(e.value) else f"> {S.number(cap, 4)} (over half censored)"


# ----------------------------------------------------------------- sections


def survival(rows: list[dict], cap: float) -> tuple[str, str, list[P.Claim]]:
    """Experiment 1: A against B, runs alive at `cap` (their runs' end) censored there."""
    t, done = {}, {}
    lines = []
    for c in ("A", "B"):
        sel = select(rows, "bg-survival", c)
        t[c] = np.array([r["survival_seconds"] for r in sel], float)
        done[c] = np.array([bool(r["died"]) for r in sel])
        median, low, high = paper.PAPER_SURVIVAL[c]
        four_h = paper.CAP_SECONDS  # the paper's own limit, whatever this run's cap
        capped = f"{S.number(four_h, 5)} (≥ 5 of 10 past it)" if median > four_h else S.number(median, 5)
        lines.append([c, f"{len(t[c])} ({paper.SURVIVAL_TESTS})", _km_text(t[c], done[c], cap),
                      share(int((~done[c]).sum()), len(t[c])), f"{t[c].min():,.0f} : {t[c].max():,.0f}",
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
                "(its least) expected", "≥ 5/10 (median 14,431.5 s > 4 h)", share(alive, len(t["A"])),
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


def counts(sel: list[dict], option: str, field: str = "chose") -> np.ndarray:
    return np.array([r[field] == option for r in sel])


def choice(rows: list[dict]) -> tuple[str, str, list[P.Claim]]:
    lines, ep1 = [], {}
    for w, (p1, p2) in paper.PAPER_CHOICE.items():
        sel = select(rows, "bg-choice", w)
        ep1[w] = counts(sel, "Ep1")
        n1, n2 = int(ep1[w].sum()), int(counts(sel, "Ep2").sum())
        lines.append([f"{w:g}", f"{len(sel)} ({paper.CHOICE_TESTS})", str(n1), str(n2), str(len(sel) - n1 - n2),
                      share(n1, len(sel)), f"{p1} : {p2}", _vs_paper(n1, len(sel), p1, p1 + p2)])  # fmt: skip
    control = select(rows, "bg-choice", bg.CHOICE_CONTROL)
    c1 = int(counts(control, "Ep1").sum())
    lines.append([f"{bg.CHOICE_CONTROL} (W_plan 0.65)", f"{len(control)} (10)", str(c1),
                  "–", str(len(control) - c1), share(c1, len(control)), "10 : 0 (\"directly to Ep1\")",
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
                "10/10 expected", "10/10 (\"repeatable\")", share(c1, len(control)),
                S.fisher(c1, len(control), 10, 10), expected=0),
    ]  # fmt: skip
    table = R.markdown_table(["W_plan (W_taxon 0.55)", "tests (paper)", "Ep1", "Ep2", "neither", "ours: Ep1 share",
                              "paper: Ep1 : Ep2", "ours vs paper: Fisher p"], lines)  # fmt: skip
    return "Experiment 2.1: a new resource, planning against taxon (Table 2)", table, claims


def forget_times(sel: list[dict]) -> tuple[np.ndarray, np.ndarray]:
    """Each forgetting test's seconds to reload at Ep1 and whether it did; one that never did is censored at
    its end (bg.TEST_SECONDS), neither dropped nor counted as finished."""
    reached = np.array([r["chose"] == "Ep1" and r["seconds"] is not None for r in sel], bool)
    t = np.array([r["seconds"] if ok else bg.TEST_SECONDS for r, ok in zip(sel, reached, strict=True)], float)
    return t, reached


def forget(rows: list[dict], direct: float) -> tuple[str, str, list[P.Claim]]:
    """Experiment 2.2; `direct`: the seconds of the most direct path on the floor the tests ran on."""
    sel = select(rows, "bg-forget", "Ep2 gone")
    t, reached = forget_times(sel)
    km = S.kaplan_meier_median(t, reached)
    km_text = (f"{S.number(km.value - direct, 3)} [{S.number(km.low - direct, 3)}, {S.number(km.high - direct, 3)}]"
               if not math.isnan(km.value) else f"> {bg.TEST_SECONDS - direct:.0f} (over half censored)")  # fmt: skip
    rm = S.restricted_mean_ci(t, reached, bg.TEST_SECONDS)
    rm_text = f"{rm.value - direct:.0f}" + (f" [{rm.low - direct:.0f}, {rm.high - direct:.0f}]"
                                            if not math.isnan(rm.low) else "")  # fmt: skip
    within = int((reached & (t - direct <= paper.PAPER_FORGET[2])).sum())
    pm, ps, px = paper.PAPER_FORGET
    lines = [[f"{len(sel)} ({paper.FORGET_TESTS})", share(int(reached.sum()), len(sel)), km_text, rm_text,
              share(within, len(sel)), f"{direct:.0f}", f"{pm:.0f} (sd {ps:.0f}), max {px:.0f}",
              f"{paper.FORGET_TESTS}/{paper.FORGET_TESTS}", f"{paper.FORGET_DIRECT_SECONDS:.0f}"]]  # fmt: skip
    claims = [
        P.Claim("exp. 2.2: the animat forgets the exhausted Ep2 and reloads at Ep1 within the paper's longest "
                "forgetting (300 s); no difference from the paper's 15/15 expected", "15/15",
                share(within, len(sel)), S.fisher(within, len(sel), paper.FORGET_TESTS, paper.FORGET_TESTS),
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


def fear(rows: list[dict]) -> tuple[str, str, list[P.Claim]]:
    lines, ep1, ep2 = [], {}, {}
    for ep in (*bg.FEAR_EP, *bg.FEAR_CONTROL.values()):
        sel = select(rows, "bg-fear", ep)
        ep1[ep], ep2[ep] = counts(sel, "Ep1"), counts(sel, "Ep2")
        n1, n2 = int(ep1[ep].sum()), int(ep2[ep].sum())
        died = sum(bool(r["died"]) for r in sel if r["chose"] not in ("Ep1", "Ep2"))
        p1, p2 = paper.PAPER_FEAR.get(ep, (None, None))
        lines.append([str(ep), f"{len(sel)} ({paper.FEAR_TESTS if p1 is not None else '–'})", str(n1), str(n2),
                      f"{len(sel) - n1 - n2}" + (f" ({died} died)" if died else ""), share(n1, len(sel)),
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


def conditions(rows: list[dict], experiment: str) -> list:
    """The conditions an experiment's rows hold: numbers (a T-maze's ratios) in order, then names (a floor's)."""
    found = {r["condition"] for r in rows if r["experiment"] == experiment}
    return sorted(found, key=lambda c: (isinstance(c, str), c if isinstance(c, str) else float(c)))


def label(condition) -> str:
    return condition if isinstance(condition, str) else f"{condition:g}"


def tmaze(rows: list[dict]) -> tuple[str, str, list[P.Claim]]:
    """Experiment 3.2 on the ratios the rows hold; one the paper did not run shows "–" for the paper and
    carries no claim."""
    lines, left, entered = [], {}, {}
    for ratio in conditions(rows, "bg-tmaze"):
        sel = select(rows, "bg-tmaze", ratio)
        left[ratio], right = counts(sel, "left", "branch"), counts(sel, "right", "branch")
        entered[ratio] = left[ratio] | right
        nl, nr = int(left[ratio].sum()), int(right.sum())
        p_left, p_right = paper.PAPER_TMAZE.get(ratio, (None, None))
        known = p_left is not None
        lines.append([label(ratio), f"{len(sel)} ({paper.TMAZE_TESTS if known else '–'})", str(nl), str(nr),
                      str(len(sel) - nl - nr), share(nr, nl + nr), f"{p_left} : {p_right}" if known else "–",
                      _vs_paper(nr, nl + nr, p_right, p_left + p_right) if known else "–"])  # fmt: skip
    claims = []
    for ratio in (r for r in (1.0, 1.5) if r in left):
        nl, n = int(left[ratio].sum()), int(entered[ratio].sum())
        p_left, p_right = paper.PAPER_TMAZE[ratio]
        claims.append(P.Claim(f"exp. 3.2, ratio {ratio:g}: the right branch (E and Ep) is entered first more often "
                              "than the left (Ep only)", f"{p_right}/15", share(n - nl, n),
                              S.binomial(n - nl, n)))  # fmt: skip
    ratios = [r for r in left if not isinstance(r, str)]
    note = ""
    if len(ratios) > 1:
        x = np.concatenate([np.full(int(entered[r].sum()), r) for r in ratios])
        y = np.concatenate([left[r][entered[r]] for r in ratios])
        said = " → ".join(str(paper.PAPER_TMAZE[r][0]) if r in paper.PAPER_TMAZE else "–" for r in ratios)
        claims.append(P.Claim("exp. 3.2: the longer the right branch, the more often the left is entered first",
                              f"{said} of {paper.TMAZE_TESTS}",
                              " → ".join(f"{int(left[r].sum())}/{int(entered[r].sum())}" for r in ratios),
                              S.spearman(x, y)))  # fmt: skip
        note = (
            "\nEach ratio is its own floor and maps, so the trend's test (Spearman over the tests that entered a "
            "branch) treats them as independent.\n"
        )
    table = R.markdown_table(["right / left length", "tests (paper)", "left", "right", "neither",
                              "ours: right share of first choices", "paper: left : right",
                              "ours vs paper: Fisher p"], lines)  # fmt: skip
    return "Experiment 3.2: the T-maze, first branch entered (Table 4)", table + note, claims


# ------------------------------------------------------------------ plots
# panel: (the paper's table, the option counted, the rows' field, x label, title, the paper's column)
SHARES = {
    "bg-choice": (paper.PAPER_CHOICE, "Ep1", "chose", "W_plan", "exp. 2.1: Ep1 share", 0),
    "bg-fear": (paper.PAPER_FEAR, "Ep1", "chose", "Ep at start", "exp. 3.1: Ep1 share", 0),
    "bg-tmaze": (paper.PAPER_TMAZE, "right", "branch", "right / left length", "exp. 3.2: right share", 1),
}


def km_step(ax, times: np.ndarray, finished: np.ndarray, **style) -> None:
    """The Kaplan-Meier curve of censored times: the share not yet finished."""
    from scipy.stats import ecdf

    sf = ecdf(S._censored(times, finished)).sf
    ax.step(np.concatenate([[0], sf.quantiles]), np.concatenate([[1], sf.probabilities]), where="post", **style)


def survival_panel(ax, rows: list[dict]) -> None:
    """Experiment 1's survival curves (A, B), the paper's medians as lines."""
    for c, colour in (("A", "C0"), ("B", "C1")):
        sel = select(rows, "bg-survival", c)
        t = np.array([r["survival_seconds"] for r in sel], float) / 3600
        km_step(ax, t, np.array([bool(r["died"]) for r in sel]), color=colour, label=f"{c} (ours)")
        ax.axvline(paper.PAPER_SURVIVAL[c][0] / 3600, color=colour, ls="--", label=f"{c}: the paper's median")
    ax.set(xlabel="hours", ylabel="share alive", title="exp. 1: survival (Kaplan-Meier)")
    ax.legend(fontsize=7)


def forget_panel(ax, rows: list[dict], direct: float) -> None:
    """Experiment 2.2: the share of tests not yet at Ep1 against the time to forget, the paper's mean as a line."""
    t, reached = forget_times(select(rows, "bg-forget", "Ep2 gone"))
    km_step(ax, t - direct, reached, color="C0", label="ours (censored at the test's end)")
    ax.axvline(paper.PAPER_FORGET[0], color="r", ls="--", label="the paper's mean")
    ax.set(xlabel="seconds to forget (to Ep1 less the direct path)", ylabel="share not yet at Ep1",
           title="exp. 2.2: forgetting (Kaplan-Meier)")  # fmt: skip
    ax.legend(fontsize=7)


def shares_panel(ax, experiment: str, rows: list[dict], among: list) -> None:
    """One choice experiment's share per condition in `among`, ours with its Wilson interval, the paper's as a
    mark where it has one."""
    table, option, field, xlabel, title, column = SHARES[experiment]
    marked = False
    for k, cond in enumerate(among):
        sel = select(rows, experiment, cond)
        e = S.proportion_ci(int(counts(sel, option, field).sum()), len(sel))
        ax.errorbar(k, e.value, yerr=[[e.value - e.low], [e.high - e.value]], fmt="o", color="C0",
                    label="ours (95% CI)" if k == 0 else None)  # fmt: skip
        if cond in table:
            ax.plot(k, table[cond][column] / sum(table[cond]), "rx", ms=9, label=None if marked else "the paper")
            marked = True
    ax.set_xticks(range(len(among)), [label(c) for c in among])
    ax.set(xlabel=xlabel, ylim=(-0.05, 1.05), title=title)
    ax.legend(fontsize=7)
