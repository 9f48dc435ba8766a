"""How a mapping animat makes the "previously built map" of experiments 2 and 3, declared once.

The paper gives its animat a map built beforehand and does not say how.  Ours is built the way
experiment 1 starts, by "random exploration and map building": a mapping animat lives on the floor
until its own map holds every kind of resource there (a node that learned it), or a time budget runs
out.  Every number of that procedure is declared here with its reason (swarm.core.params); the
reproduction's parameters page lists them beside the animat's.
"""

from __future__ import annotations

from dataclasses import dataclass

from swarm.core.params import OURS, declared


@dataclass(frozen=True)
class MappingParams:
    """The mapping phase of experiments 2 and 3 (the paper: "a previously built map", nothing more)."""

    seconds: float = declared(
        7200.0,
        source=OURS,
        reason="s, the most a mapping run lasts: the paper does not say how long its map took; two hours of "
        "life is many crossings of the paper's floors at the animat's speed, so a run ends on the animat's "
        "own map, not on this budget, unless it never finds a resource",
    )
    least_seconds: float = declared(
        1800.0,
        source=OURS,
        reason="s an exploring mapping run goes on before its map may count as done: without it the map "
        "ends at the first resources found and holds one corridor, where the paper's tests start from a "
        "map of the floor",
    )
    energy: float = declared(
        0.5,
        source=OURS,
        reason="E at the start of mapping: half full, so that the animat seeks both resources and reloads "
        "there, which is how its map learns them",
    )
    potential: float = declared(0.5, source=OURS, reason="Ep at the start of mapping, as E")
    lifetime: float = declared(
        4 * 3600.0,
        source=OURS,
        reason="s a full E lasts while mapping (the paper's animat: 33 min): mapping is learning the floor, "
        "not surviving it, and an animat that dies mid-map leaves no map to test",
    )
    danger_rate: float = declared(
        0.0,
        source=OURS,
        reason="E lost per second in a dangerous area while mapping: none, for the same reason; the tests of "
        "experiment 3.1 pay the declared rate",
    )


MAPPING_PARAMS = MappingParams()
