"""What the rules the paper leaves open do: an ablation of rules 5 and 6 of docs/cmarking.md.

Rule 5: a returner that loaded on a coloured cell either mends the trail home (ours: it follows the
trail down and colours only its gaps) or, read literally, descends the marks without colouring.
Rule 6: after unloading, the agent remembers the cell it came from (the paper's text: it does not
climb straight back up its own trail) or forgets it.  Each alternative is run against ours on the
same maps (a seed is a map), so the comparison is paired; the table shows what each rule does, not
which reading comes closer to the paper.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from swarm.experiments import stats as S
from swarm.experiments.protocol import p_text

OURS = ("mend", "remember")
VARIANTS = (OURS, ("descend", "remember"), ("mend", "forget"), ("descend", "forget"))
# (scenario, agents): setup 1 at 10 agents, setup 2's lone agent and pair (the super-linearity), setup 3 large
CONFIGS = (("setup1", 10), ("setup2", 1), ("setup2", 2), ("setup3-100", 50))
CAP = 1_000_000
FIELDS = ["experiment", "scenario", "agents", "return_on_trail", "at_base", "seed", "iterations", "finished",
          "wall_seconds"]  # fmt: skip


def jobs(seeds: range) -> list[tuple]:
    return [(scenario, agents, rule, at_base, seed) for scenario, agents in CONFIGS
            for rule, at_base in VARIANTS for seed in seeds]  # fmt: skip


def run_rule(job: tuple) -> dict:
    from swarm.engines.grid import Engine
    from swarm.scenario import load_scenario

    scenario, agents, rule, at_base, seed = job
    s = load_scenario(scenario).with_overrides(agents=agents, controller="cmarking", seed=seed)
    s = replace(s, cmarking=replace(s.cmarking, return_on_trail=rule, at_base=at_base))
    summary = Engine(s).run("foraged", CAP).summary
    return {"experiment": "rules", "scenario": scenario, "agents": agents, "return_on_trail": rule, "at_base": at_base,
            "seed": seed, "iterations": summary["iterations"], "finished": summary["finished"],
            "wall_seconds": summary["wall_seconds"]}  # fmt: skip


def _times(rows: list[dict], scenario: str, agents: int, variant: tuple[str, str]) -> np.ndarray:
    sel = sorted((r for r in rows if r["scenario"] == scenario and r["agents"] == agents
                  and (r["return_on_trail"], r["at_base"]) == variant), key=lambda r: r["seed"])  # fmt: skip
    return np.array([r["iterations"] for r in sel], float)


def section(rows: list[dict]) -> tuple[str, str]:
    """(title, markdown table): each variant's time beside ours, their paired ratio with its interval, the
    Wilcoxon signed-rank test, and the super-linearity of setup 2 (T(1)/2 - T(2)) under each variant."""
    lines = ["| configuration | rule 5 | rule 6 | iterations (95% CI) | variant / ours (95% CI) | Wilcoxon p | "
             "unfinished |", "|---|---|---|---|---|---|---|"]  # fmt: skip
    for scenario, agents in CONFIGS:
        ours = _times(rows, scenario, agents, OURS)
        for variant in VARIANTS:
            t = _times(rows, scenario, agents, variant)
            unfinished = sum(not r["finished"] for r in rows if r["scenario"] == scenario and r["agents"] == agents
                             and (r["return_on_trail"], r["at_base"]) == variant)  # fmt: skip
            if variant == OURS:
                ratio, p = "1 (ours)", "–"
            else:
                est, _ = S.ratio_of_means(t, ours, paired=True)
                ratio, p = est.text(3), p_text(S.wilcoxon_paired(t, ours).p)
            lines.append(f"| {scenario}, {agents} agents | {variant[0]} | {variant[1]} | {S.mean_ci(t).text(3)} | "
                         f"{ratio} | {p} | {unfinished}/{len(t)} |")  # fmt: skip
    lines += ["", "| rule 5 | rule 6 | setup 2: T(1)/2 - T(2) (95% CI) |", "|---|---|---|"]
    for variant in VARIANTS:
        one, two = _times(rows, "setup2", 1, variant), _times(rows, "setup2", 2, variant)
        lines.append(f"| {variant[0]} | {variant[1]} | {S.mean_ci(one / 2 - two).text(3)} |")
    return "Rules the paper leaves open: what rules 5 and 6 do (ablation)", "\n".join(lines) + "\n"
