"""C-marking's and the pheromone ant's one declared parameter set (Simonin, Charpillet & Thierry
2007), with the bodies of the grid world's robots, each value with its provenance.

PAPER: the marking rule (Algorithm 2, sections 3.1-3.2), the ants' diffusion and evaporation
(section 5.5) and the ideal cell-to-cell moves (section 5.1).  CODE: NetLogo's Ants model, which the
paper's ant baseline follows.  OURS: what the paper leaves open, each with its reason: c-marking's
patience and its readings of rules 5 and 6, the ants' deposit, threshold and detours
(docs/cmarking.md), and the physical bodies (docs/physics.md).  The scenario's [cmarking], [ant] and
[physics] tables set them; the compiled world and controllers read them from the rows the world
writes (face/layout.py).
"""

from __future__ import annotations

from dataclasses import dataclass

from swarm.core.params import CODE, OURS, PAPER, declared


@dataclass(frozen=True)
class MarkingRule:
    """The marking agents' numbers (Algorithm 2): the marking, c-marking and ant controllers have no
    other free number in their marks.  `update_value` and the world write them as literals; this
    records their provenance (nothing reads it)."""

    step: int = declared(
        1, source=PAPER, where="section 3.1, Algorithm 2, UPDATE-VALUE: val = min(val, 1 + min(4-neighbour values))"
    )
    base: int = declared(
        0,
        source=PAPER,
        where="section 3.2: the base cell c_0 is assigned its optimal value 0 before agents begin exploring",
    )


@dataclass(frozen=True)
class AntParams:
    """The pheromone ant baseline: NetLogo's Ants model (section 5.5; docs/cmarking.md, "The ant baseline")."""

    diffusion: float = declared(0.95, source=PAPER, where="section 5.5: the diffusion rate is set to 95%")
    evaporation: float = declared(0.005, source=PAPER, where="section 5.5: the evaporation rate to 0.5%")
    deposit: float = declared(
        1.0,
        source=OURS,
        reason="the paper gives no amount; only its ratio to `threshold` "
        "matters, so one unit per cell crossed (docs/cmarking.md, the ant baseline)",
    )
    threshold: float = declared(
        0.001,
        source=OURS,
        reason="the paper does not give its ant model's rule; the best of 25 settings of "
        "`swarm experiment tuning` on development seeds, the budget c-marking's climb_patience had",
    )
    ceiling: float = declared(
        0.04,
        source=OURS,
        reason="NetLogo's window [0.05, 2) is 40 x its floor; kept at 40 x threshold",
    )
    wiggle: float = declared(
        40,
        source=CODE,
        where="NetLogo Ants model: `rt random 40 lt random 40` each step; also the tuning's best",
    )
    detour: float = declared(
        8,
        source=OURS,
        reason="random steps when both compass directions are walled: without "
        "them ants freeze forever in concave pockets (Figure 11.a; docs/cmarking.md)",
    )


@dataclass(frozen=True)
class CMarkingParams:
    """The c-marking agents' open numbers and the two rules the paper leaves open (docs/cmarking.md)."""

    climb_patience: int = declared(
        20,
        source=OURS,
        reason="a climber circling a loop of trail cells (two parallel "
        "trails make 2x2 loops) livelocks under the literal rules; after this many climb "
        "steps without a higher mark it wipes and erases (docs/cmarking.md, choice 9)",
    )
    return_on_trail: str = declared(
        "mend",
        source=OURS,
        reason="rule 5: a returner that loaded on a coloured cell mends the trail home; "
        "the literal reading `descend` leaves gaps (the report's ablation shows both)",
    )
    at_base: str = declared(
        "remember",
        source=OURS,
        reason="rule 6: the literal reading of 'coloured neighbours different from the previous "
        "position' right after unloading; `forget` is the alternative (the report's ablation shows both)",
    )


@dataclass(frozen=True)
class PhysicsParams:
    """Robot bodies (world_server/grid/bodies.py).  Lengths in cells, times in seconds."""

    mode: str = declared(
        "ideal",
        source=PAPER,
        where="section 5.1: one iteration, each agent moves to a "
        "neighbouring cell (ideal: instant cell-to-cell moves; physical: pymunk discs, ours)",
    )
    diameter: float = declared(
        0.4, source=OURS, reason="body diameter in cells: two fit side by side in a corridor (docs/physics.md)"
    )
    speed: float = declared(2.0, source=OURS, reason="top speed, cells per second (docs/physics.md)")
    timeout: float = declared(
        2.0,
        source=OURS,
        reason="longest simulated time one tick may take: a cell is crossed in 0.5 s at top speed (docs/physics.md)",
    )
    dt: float = declared(0.05, source=OURS, reason="physics step, s (docs/physics.md)")
    arrive: float = declared(
        0.2,
        source=OURS,
        reason="a body has reached a cell when its centre is this close to the cell's centre (docs/physics.md)",
    )
