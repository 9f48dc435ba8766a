"""`swarm experiment bg-survival | bg-choice | bg-forget | bg-fear | bg-tmaze`: one experiment of Girard et
al. (2005) on its floor or the user's, with any reps, seed, ratios and [bg] changes.

The runs are bg.py's; the table is the report's section for that experiment (sections.py): the paper's
claims with our tests and verdicts, then the section's table with intervals, the paper beside ours.  The
table's head says which seed range the runs drew from: only the confirmation range's are evidence
(swarm/experiments/protocol.py; `swarm reproduce girard2005` runs them).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from swarm.core.errors import ScenarioError
from swarm.experiments import protocol as P
from swarm.experiments import report as R
from swarm.experiments.girard2005 import sections
from swarm.experiments.girard2005.bg import (
    MAPPING,
    MAPPING_MODES,
    MAPPING_SECONDS,
    REPS,
    check_floors,
    direct_seconds,
    make_maps,
    reps_and_maps,
    run_survival,
    run_test,
    test_jobs,
)
from swarm.experiments.girard2005.mapping import MAPPING_PARAMS
from swarm.experiments.runner import Outputs, batch_run
from swarm.scenario import load_scenario

CHOSEN = {"bg-choice": sections.choice, "bg-fear": sections.fear, "bg-tmaze": sections.tmaze}


def run_bg_experiment(experiment: str, scenario: str | None, reps: int | None, jobs: int | None, seed: int,
                      out: Path | None, ratios: tuple[float, ...] | None = None, maps: int | None = None,
                      progress: bool = True, bg: dict[str, Any] | None = None,
                      mapping: str | None = None, max_ticks: int | None = None,
                      mapping_seconds: float = MAPPING_SECONDS) -> dict:  # fmt: skip
    """Run one experiment on its floor (or `scenario`, a file with the resources bg.FLOOR_NEEDS names); `maps`
    mapping runs per floor for experiments 2 and 3 (default: one per test), made as `mapping` says
    (bg.MAPPING_MODES; default bg.MAPPING), each at most `mapping_seconds`; `bg` changes the [bg] table of
    every run (mapping runs included); `max_ticks` cuts survival runs short (a smoke run), and the tables
    censor them there."""
    changes = dict(bg or {})
    floors = check_floors(experiment, scenario, ratios, changes)
    reps, maps, mapping = _checked(experiment, reps, maps, mapping)
    out_ = Outputs(out, experiment)
    cap = survival_cap(floors[0], max_ticks) if experiment == "bg-survival" else 0.0
    direct = direct_seconds(floors[0]) if experiment == "bg-forget" else 0.0
    if experiment == "bg-survival":
        work = [(c, k, seed + k, changes, max_ticks, floors[0]) for c in ("A", "B") for k in range(reps)]
        rows = batch_run(run_survival, work, jobs=jobs, desc=experiment, progress=progress)
        rows.sort(key=lambda r: (r["condition"], r["run"]))
        head = f"{reps} runs per condition on {floors[0]}, each until death or {cap:,.0f} s (the runs' cap)."
    else:
        made = make_maps(experiment, maps, seed, floors, jobs, progress, changes, mapping, mapping_seconds)
        (out_ / "maps.json").write_text(json.dumps(made))
        work = test_jobs(experiment, reps, seed, made, changes)
        rows = batch_run(run_test, work, jobs=jobs, desc=experiment, progress=progress)
        rows.sort(key=lambda r: (str(r["condition"]), r["run"]))
        head = _maps_head(reps, made, mapping, mapping_seconds)
    out_.runs(rows, list(rows[0]))
    tagged = [{**r, "experiment": experiment} for r in rows]
    title, table, claims = _section(experiment, tagged, cap, direct)
    head += " " + seeds_text(seed, reps) + (f"  [bg] changed in every run: {json.dumps(changes)}." if changes else "")
    result = out_.finish(
        [{"row": "claim", **R.claim_row(c)} for c in claims] + table_rows(table), _text(title, head, table, claims)
    )
    _plot(experiment, tagged, direct, out_ / "plot.png")
    return result


def _section(experiment: str, rows: list[dict], cap: float, direct: float) -> tuple[str, str, list[P.Claim]]:
    """The report's section for this experiment: survival censored at `cap`, forgetting less `direct`."""
    if experiment == "bg-survival":
        return sections.survival(rows, cap)
    if experiment == "bg-forget":
        return sections.forget(rows, direct)
    return CHOSEN[experiment](rows)


def _checked(experiment: str, reps: int | None, maps: int | None, mapping: str | None) -> tuple[int, int, str]:
    """The command line's reps, maps and mapping mode, checked: a ScenarioError naming the option."""
    reps, maps = reps_and_maps(REPS[experiment] if reps is None else reps, maps, experiment != "bg-survival")
    if experiment == "bg-survival" and mapping is not None:
        raise ScenarioError("command line", "--mapping", "bg-survival has no mapping phase (A maps as it lives)")
    mapping = MAPPING if mapping is None else mapping
    if mapping not in MAPPING_MODES:
        raise ScenarioError("command line", "--mapping", f"one of {', '.join(MAPPING_MODES)}, not {mapping!r}")
    return reps, maps, mapping


def survival_cap(floor: str, max_ticks: int | None) -> float:
    """The seconds a survival run on `floor` lasts at most: the floor's max_ticks, or `max_ticks` where given."""
    s = load_scenario(floor)
    return (s.max_ticks if max_ticks is None else max_ticks) * s.control_period


def seeds_text(first: int, n: int) -> str:
    """Which range runs first .. first + n - 1 drew their seeds from, and whether that makes them evidence."""
    last, confirm = first + n - 1, P.CONFIRMATION_SEEDS
    if P.is_confirmation(first) and P.is_confirmation(last):
        return f"Seeds {first}..{last}, from the confirmation range."
    where = "the development range" if last in P.DEVELOPMENT_SEEDS else "outside the confirmation range"
    return (f"**Seeds {first}..{last}, from {where}: not evidence** (reported numbers come from the confirmation "
            f"range, {confirm.start}..{confirm.stop - 1}: `--seed {confirm.start}`, or `swarm reproduce "
            "girard2005`).")  # fmt: skip


def _text(title: str, head: str, table: str, claims: list[P.Claim]) -> str:
    """table.md: the head, the verdict rule, the claims with verdicts, then the section's table."""
    said = P.claims_table(claims) if claims else "No claim of the paper applies to these conditions.\n"
    heading = f"# Girard et al. (2005), {title[0].lower()}{title[1:]}"
    return f"{heading}\n\n{head}\n\n{R.VERDICT_RULE}\n\n## Claims\n\n{said}\n## Table\n\n{table}"


def table_rows(table: str) -> list[dict]:
    """The rows of a section's markdown table as summary.csv rows, one per condition (its cells by header)."""
    lines = [line.strip().strip("|").split(" | ") for line in table.splitlines() if line.startswith("| ")]
    header = [cell.strip() for cell in lines[0]]
    return [{"row": "table", **dict(zip(header, (cell.strip() for cell in line), strict=True))} for line in lines[1:]]


def _maps_head(reps: int, maps: dict[str, list[dict]], mapping: str, seconds: float) -> str:
    """How the tests' maps were made and what they hold."""
    held = "; ".join(f"{name}: {_maps_line(made)}" for name, made in maps.items())
    n = len(next(iter(maps.values())))
    p = MAPPING_PARAMS
    if n == 1:
        which = "every test on the map of one mapping run"
    elif n == reps:
        which = "test k of every condition on the map of mapping run k (seed + k)"
    else:
        which = f"test k of every condition on the map of mapping run k mod {n} (seed + k mod {n})"
    return (f"{reps} tests per condition; {which} ({held}).  A mapping animat lives in the scenario (E = "
            f"{p.energy}, Ep = {p.potential} at the start, a full E lasting {p.lifetime / 3600:g} h, the saliences "
            "of exp. 1; girard2005/mapping.py) until its own map holds every kind of resource on the floor, or "
            f'{seconds / 60:g} min (mapping "{mapping}"{MAPPING_MODES[mapping].text}.  A test is the '
            "same animat: it goes on mapping from the map it loads.")  # fmt: skip


def _maps_line(made: list[dict]) -> str:
    """What the maps of one scenario hold: nodes, mapping time, resources been at, nodes holding each kind."""

    def spread(values) -> str:
        lo, mid, hi = min(values), float(np.median(values)), max(values)
        return f"{lo:.0f}" if lo == hi else f"median {mid:.0f} ({lo:.0f} : {hi:.0f})"

    visited = sorted({v for m in made for v in m["visited"]})
    kinds = sorted({r for m in made for r in m["assoc"]})
    holding = {r: spread([sum(w > 0.5 for w in m["assoc"].get(r, [])) for m in made]) for r in kinds}
    return (f"{len(made)} map{'s' if len(made) > 1 else ''}, {spread([len(m['map']['nodes']) for m in made])} nodes "
            f"after {spread([m['mapped_seconds'] / 60 for m in made])} min; been at "
            + ", ".join(f"{v} {sum(v in m['visited'] for m in made)}" for v in visited)
            + "; nodes holding " + ", ".join(f"{r} {h}" for r, h in holding.items()))  # fmt: skip


def _plot(experiment: str, rows: list[dict], direct: float, path: Path) -> None:
    """The report's panel for this experiment: survival or forgetting curves (Kaplan-Meier), or the shares of
    each condition with their intervals, the paper's beside them (its conditions first, in its order)."""
    from swarm.core.plots import pyplot, save_figure

    fig, ax = pyplot().subplots(figsize=(6, 4))
    if experiment == "bg-survival":
        sections.survival_panel(ax, rows)
    elif experiment == "bg-forget":
        sections.forget_panel(ax, rows, direct)
    else:
        found, paper = sections.conditions(rows, experiment), list(sections.SHARES[experiment][0])
        sections.shares_panel(
            ax, experiment, rows, [c for c in paper if c in found] + [c for c in found if c not in paper]
        )
    save_figure(fig, path)
