"""`swarm reproduce billing2015`: the claims of section 5 (cases 1, 2 and 3) beside ours, on the confirmation seeds.

Cases 1 and 2 run every start/goal pair under the paper's five conditions (SPA at low and high noise, follow
the carrot at none, low and high), follow the carrot both as ours (FTC) and as Appendix B prints it (FTCp).
A pair's seed is the same in every condition, so success is compared pair by pair (McNemar) and the paper's
one-way ANOVA of L_p / L_o is given beside it, over the five with each follow the carrot.  Case 3 draws the
obstacle's appearance t_i and duration t_p per run, as the paper did, and judges the paper's three
statements about the route the robot takes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from swarm.experiments import protocol as P
from swarm.experiments import report as R
from swarm.experiments import stats as S
from swarm.experiments.billing2015 import paper
from swarm.experiments.billing2015.carrot import PAPER_FTC, RUN_FIELDS, arm, ftc_name, run_pair
from swarm.experiments.billing2015.dft import (
    CASE3_BOXES,
    CASE3_FIELDS,
    CONDITIONS,
    ROUTE_COLOUR,
    case3_jobs,
    five,
    label,
    pair_jobs,
    plot_case3,
    plot_case3_paths,
    plot_pairs,
    run_case3,
)
from swarm.experiments.runner import Outputs, batch_run

TITLE = "Billing, Lowe & Sandamirskaya (2015)"
CONTROLLERS = ("dft", "carrot")
# start/goal pairs per case (the paper's 100) and case 3 runs per obstacle type and noise level
REPS = {"case1": paper.PAIRS, "case2": paper.PAIRS, "case3": 60}
QUICK_REPS = {"case1": 8, "case2": 3, "case3": 4}
QUICK_CASE2_STEPS = 1000  # --quick cuts the large maze's runs short: its successes are not evidence
CASE_OF = {"case1": "dft-case1", "case2": "dft-case2"}
SUCCESS_RADIUS = 0.07  # m: a pair whose goal is this close to its start is reached before it starts
PAIR_FIELDS = ["case", "seed", *RUN_FIELDS]
CASE3_CSV_FIELDS = ["case", "seed", *CASE3_FIELDS]
DESIGN = ("Cases 1 and 2: every start/goal pair under the five conditions, follow the carrot both as ours (FTC) and "
          "as Appendix B prints it (FTCp), a pair's seed shared by all, so "
          "success is compared pair by pair (exact McNemar); 'most runs' is tested against one half (exact "
          "binomial); L_p / L_o by the paper's one-way ANOVA over the reached runs. Case 3: t_i and t_p drawn per "
          "run. Proportions with Wilson 95% intervals, means with bootstrap (BCa) ones.")  # fmt: skip


def plan(reps: dict[str, int], quick: bool) -> list[tuple]:
    """Every run: (kind, case, the experiment's own job), the long large-maze runs first."""
    seed = P.CONFIRMATION_SEEDS.start
    case2_steps = QUICK_CASE2_STEPS if quick else None
    jobs = [("pair", "case2", j) for j in pair_jobs(CASE_OF["case2"], reps["case2"], seed, case2_steps)]
    jobs += [("pair", "case1", j) for j in pair_jobs(CASE_OF["case1"], reps["case1"], seed, None)]
    jobs += [("case3", "case3", j) for j in case3_jobs(reps["case3"], seed, ("low", "high"), None)]
    return jobs


def run_job(job: tuple) -> dict:
    """One run, its row tagged with its case and the seed that drove it."""
    kind, case, j = job
    if kind == "pair":
        return {"case": case, "seed": j[8]} | run_pair(j)
    return {"case": case, "seed": j[5]} | run_case3(j)


def reproduce(quick: bool = False, jobs: int | None = None, out: Path | None = None, progress: bool = True) -> dict:
    reps = QUICK_REPS if quick else REPS
    out_ = Outputs(out if out is not None else Path("results") / "reproduce" / "billing2015", "billing2015")
    rows = batch_run(run_job, plan(reps, quick), jobs=jobs, desc="billing2015", progress=progress)
    order = [label(c, n) for c, n in CONDITIONS]
    pairs = sorted((r for r in rows if r["case"] != "case3"),
                   key=lambda r: (r["case"], order.index(label(arm(r), r["noise"])), r["pair"]))  # fmt: skip
    case3 = sorted((r for r in rows if r["case"] == "case3"), key=lambda r: (r["obstacle"], r["noise"], r["run"]))
    out_.runs(pairs, PAIR_FIELDS)
    out_.runs(case3, CASE3_CSV_FIELDS, file="case3.csv")
    sections, claims = [], []
    for case in ("case1", "case2"):
        sel = [r for r in pairs if r["case"] == case]
        plot_pairs(sel, out_ / f"{case}.png")
        title, table, cs = _pairs_section(case, sel, quick)
        sections.append((title, f"{table}\n![{case}]({case}.png)\n"))
        claims += cs
    plot_case3(case3, out_ / "case3.png")
    plot_case3_paths(case3, out_ / "case3-paths.png")
    title, table, cs = _case3_section(case3)
    sections.append((title, f"{table}\n![case 3](case3.png)\n\n![case 3 paths](case3-paths.png)\n"))
    claims += cs
    sections += [("Known differences", "\n".join(f"- {d}" for d in paper.KNOWN_DIFFERENCES)),
                 R.parameters_section(CONTROLLERS)]  # fmt: skip
    (out_ / "parameters.md").write_text(R.parameters_page(TITLE, CONTROLLERS))
    text = R.report_text(TITLE, DESIGN, claims, sections, reps, quick)
    result = out_.finish([R.claim_row(c) for c in claims], text, file="report.md")
    return result | {"claims": len(claims), "verdicts": R.tally(claims)}


# ------------------------------------------------------------------ cases 1, 2


def _degenerate(r: dict) -> bool:
    return math.hypot(r["goal_x"] - r["start_x"], r["goal_y"] - r["start_y"]) < SUCCESS_RADIUS


def _by_pair(rows: list[dict], controller: str, noise: str) -> dict[int, dict]:
    return {r["pair"]: r for r in rows if arm(r) == controller and r["noise"] == noise}


def _pairs_section(case: str, rows: list[dict], quick: bool):
    maze = "the Z-maze" if case == "case1" else "the large maze"
    kept = [r for r in rows if not _degenerate(r)]
    left_out = len({r["pair"] for r in rows}) - len({r["pair"] for r in kept})
    lines, groups = [], {}
    for controller, noise in CONDITIONS:
        sel = [r for r in kept if arm(r) == controller and r["noise"] == noise]
        ok = sum(bool(r["reached"]) for r in sel)
        ratios = np.array([r["path_ratio"] for r in sel if r["path_ratio"] not in (None, "")], float)
        groups[(controller, noise)] = ratios
        ticks = [r["ticks_to_goal"] for r in sel if r["ticks_to_goal"] not in (None, "")]
        lines.append([label(controller, noise), S.proportion_ci(ok, len(sel)).text(3),
                      S.mean_ci(ratios).text(3) if len(ratios) > 1 else "–",
                      f"{np.median(ticks):.0f}" if ticks else "–"])  # fmt: skip
    spa_low, spa_high = _by_pair(kept, "dft", "low"), _by_pair(kept, "dft", "high")
    common = sorted(spa_low.keys() & spa_high.keys())
    low_ok = [bool(spa_low[k]["reached"]) for k in common]
    anovas = {ftc: S.anova([groups[k] for k in five(ftc)]) for ftc in ("carrot", PAPER_FTC)}
    claims = [
        P.Claim(f"{case}: SPA (low noise) reaches the goal in most runs in {maze}", "most (Fig. 7)",
                S.proportion_ci(sum(low_ok), len(low_ok)).text(3), S.binomial(sum(low_ok), len(low_ok), 0.5)),
        P.Claim(f"{case}: noise does not change SPA's successes (low against high)", "no significant effect",
                S.proportion_ci(sum(bool(spa_high[k]["reached"]) for k in common), len(common)).text(3) + " at high",
                S.mcnemar(low_ok, [bool(spa_high[k]["reached"]) for k in common]), expected=0),
    ]  # fmt: skip
    for ftc, anova in anovas.items():
        which = "" if ftc == "carrot" else ", follow the carrot as Appendix B prints it (FTCp)"
        claims.append(P.Claim(f"{case}: L_p / L_o does not differ between the five conditions{which} (one-way "
                              "ANOVA)", f"F = {paper.ANOVA_F[case]}", f"F = {anova.statistic:.2f}", anova,
                              expected=0))  # fmt: skip
    if case == "case2":
        for controller in ("carrot", PAPER_FTC):
            ftc = _by_pair(kept, controller, "low")
            both = sorted(spa_low.keys() & ftc.keys())
            which = "" if controller == "carrot" else " as Appendix B prints it (FTCp)"
            claims.append(P.Claim(f"case2: follow the carrot{which} (low noise) succeeds notably less often than SPA "
                                  "in the large maze", "notably fewer (Fig. 7)",
                                  f"SPA - {ftc_name(controller)} = "
                                  + S.number(np.mean([bool(spa_low[k]["reached"]) - bool(ftc[k]["reached"])
                                                      for k in both]), 3),
                                  S.mcnemar([bool(spa_low[k]["reached"]) for k in both],
                                            [bool(ftc[k]["reached"]) for k in both])))  # fmt: skip
    table = R.markdown_table(["condition", "reached (Wilson 95% CI)", "L_p / L_o, reached runs (95% CI)",
                              "median steps to goal"], lines)  # fmt: skip
    dropped = f"; {left_out} pairs with the goal within {SUCCESS_RADIUS * 100:.0f} cm of the start left out"
    limit = (f"--quick stops the runs at {QUICK_CASE2_STEPS} steps" if quick and case == "case2"
             else f"at most {paper.MAX_STEPS} steps of 64 ms")  # fmt: skip
    note = (
        f"\n{len({r['pair'] for r in kept})} pairs{dropped if left_out else ''}; {limit}.  FTC is our follow "
        'the carrot, FTCp Appendix B\'s as printed ([carrot] variant = "paper"), on the same pairs and seeds.\n'
    )
    return f"Case {case[-1]}: SPA beside follow the carrot in {maze}", table + note, claims


# --------------------------------------------------------------------- case 3


def case3_tally(runs: Sequence[dict]) -> dict:
    """What the paper's case-3 claims count among `runs`: the runs whose obstacle came early and those that
    went south, came late and kept north, and per obstacle the runs in between and their red switches."""
    early = [r for r in runs if r["appear"] < paper.EARLY]
    late = [r for r in runs if r["appear"] > paper.LATE]
    mid = {kind: [r for r in runs if r["obstacle"] == kind and paper.EARLY < r["appear"] < paper.LATE]
           for kind in CASE3_BOXES}  # fmt: skip
    return {"early": len(early), "south": sum(r["route"] == "south" for r in early),
            "late": len(late), "north": sum(r["route"] == "north" for r in late),
            "mid": {kind: len(sel) for kind, sel in mid.items()},
            "red": {kind: sum(r["route"] == "north-then-south" for r in sel) for kind, sel in mid.items()}}  # fmt: skip


def case3_tests(t: dict) -> tuple:
    """The tests of case 3's claims on a `case3_tally`: the early obstacle's share south and the late one's
    share north against one half (exact binomial), the red switches of full against partial boxes (Fisher)."""
    red, mid = t["red"], t["mid"]
    return (S.binomial(t["south"], t["early"], 0.5), S.binomial(t["north"], t["late"], 0.5),
            S.fisher(red["full"], mid["full"], red["partial"], mid["partial"]))  # fmt: skip


def _case3_section(rows: list[dict]):
    t = case3_tally([r for r in rows if not r["on_robot"]])
    lines = []
    for kind in CASE3_BOXES:
        for noise in ("low", "high"):
            sel = [r for r in rows if r["obstacle"] == kind and r["noise"] == noise]
            used = [r for r in sel if not r["on_robot"]]
            counts = [str(sum(r["route"] == route for r in used)) for route in ROUTE_COLOUR]
            lines.append([kind, noise, str(len(sel)), str(len(sel) - len(used)), *counts])
    red, mid = t["red"], t["mid"]
    early, late, switches = case3_tests(t)
    claims = [
        P.Claim(f"case3: an obstacle appearing before t = {paper.EARLY} sends the robot south, whatever its type",
                "south (Fig. 13-16)", S.proportion_ci(t["south"], t["early"]).text(3) + " south", early),
        P.Claim(f"case3: an obstacle appearing after t = {paper.LATE}: the robot keeps the north route",
                "always north", S.proportion_ci(t["north"], t["late"]).text(3) + " north", late),
        P.Claim(f"case3: within {paper.EARLY} < t < {paper.LATE} a full obstacle makes the robot switch north to "
                "south (red), a partial one does not", "full: red; partial: north",
                f"red: full {S.proportion_ci(red['full'], mid['full']).text(3)}, partial "
                f"{S.proportion_ci(red['partial'], mid['partial']).text(3)}", switches),
    ]  # fmt: skip
    table = R.markdown_table(["obstacle", "noise", "runs", "left out (box on the robot)", *ROUTE_COLOUR], lines)
    return "Case 3: an obstacle across the north route", table, claims
