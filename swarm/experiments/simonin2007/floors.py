"""The floor a simonin2007 experiment forages on: the paper's setups by default, or the one `--scenario`
names (a grid scenario with a base and resources), checked before any run starts so that a floor the
experiment cannot use is refused in one line."""

from __future__ import annotations

import re
from dataclasses import dataclass

from swarm.core.errors import ScenarioError

# Experiments whose design is an axis over the paper's floors, which one floor cannot give: why, in one line.
ONE_FLOOR_REFUSED = {
    "table3": "table3 varies the floor's size (setup3-12..200); --scenario gives one floor: use table1's design "
    "or a sweep",
}
HELP = {
    "table1": "run Table 1's agent counts (5..160) on this grid floor instead of setup 1 (a bundled name, a preset "
    "or a TOML file with a [map] or [generator], a base and resources); the paper's numbers only on setup1",
    "table2": "run Table 2's agent counts (1..8) on this grid floor instead of setup 2; the paper's numbers only on "
    "setup2",
    "table3": "refused: table3 varies setup 3's size, and a floor is one size (use table1's design or a sweep)",
    "ants": "compare c-marking and the ants (50 agents) on this grid floor instead of setup 3's sizes; the paper's "
    "gaps only on setup3-<size>",
    "congestion": "run the congestion study's agent counts (10..160, ideal vs physical) on this grid floor instead "
    "of setup 1; the paper's numbers only on setup1",
    "tuning": "tune both models on this grid floor instead of setup 3's sizes (not with --tuning-sizes)",
}


@dataclass(frozen=True)
class Floor:
    """A floor an experiment runs on: what load_scenario takes, its side (for the work estimate and the
    tables over sizes), its name in a table, and whether it is one of the paper's (its numbers apply)."""

    ref: str
    size: int
    label: str
    paper: bool


# The paper's floors of each experiment: where its numbers apply.
OWN_FLOORS = {"table1": r"setup1", "table2": r"setup2", "congestion": r"setup1", "ants": r"setup3-\d+",
              "tuning": r"setup3-\d+"}  # fmt: skip


def paper_floor(experiment: str, ref: str) -> bool:
    """`ref` is a preset of the paper's that the experiment's own numbers were measured on."""
    return experiment in OWN_FLOORS and re.fullmatch(OWN_FLOORS[experiment], ref) is not None


def user_floor(experiment: str, ref: str) -> Floor:
    """The floor `--scenario` names, checked: a grid scenario with a base and reachable resources."""
    from swarm.scenario import load_scenario
    from world_server.grid.scenario import Scenario

    if experiment in ONE_FLOOR_REFUSED:
        raise ScenarioError("command line", "--scenario", ONE_FLOOR_REFUSED[experiment])
    s = load_scenario(ref)  # a map without exactly one base B is refused here
    if not isinstance(s, Scenario):
        raise ScenarioError(ref, "kind", f"{experiment} forages on a grid floor ([map] ascii or [generator]), not "
                            f"on an {getattr(s, 'kind', 'other')} scenario")  # fmt: skip
    if s.generator is not None:
        if s.generator.resources < 1:
            raise ScenarioError(ref, "generator.resources", f"{experiment} needs resources to forage: give 1 or more")
        size = max(s.generator.width, s.generator.height)
        dims = f"{s.generator.width}x{s.generator.height}"
    else:
        rows = s.ascii_map or ()
        if not any("R" in row for row in rows):
            raise ScenarioError(ref, "map.ascii", f"{experiment} needs resources to forage: the map has no R")
        s.layout()  # a resource the base cannot reach is refused here
        size, dims = max(len(rows), len(rows[0])), f"{len(rows[0])}x{len(rows)}"
    return Floor(ref, size, f"{s.name} ({dims})", paper_floor(experiment, ref))


def floor_note(floor: Floor | None, numbers: bool = True) -> str:
    """The line a table gives a user's floor (`numbers`: the table has paper's numbers it leaves out)."""
    if floor is None or floor.paper:
        return ""
    left_out = ": the paper's numbers are not shown" if numbers else ""
    return f"On the user's floor {floor.label} (--scenario {floor.ref}), not the paper's{left_out}.\n\n"
