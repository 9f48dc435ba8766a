"""The marking environment's one rule, shared by the world and the grid controllers.

A robot may lower the mark of the cell it stands on to UPDATE-VALUE and no
further (Algorithm 2 of Simonin et al. 2007): the controllers compute it to
write, and the world checks every write against it before applying it.
"""

from dataclasses import dataclass

from numba import njit

from swarm.core.params import PAPER, declared
from world_server.grid.face.layout import MARK, MARK_NONE, OBST


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


@njit(cache=True, inline="always")
def update_value(pi):
    """Algorithm 2's UPDATE-VALUE: min(val, 1 + min(4-neighbour values))."""
    best = MARK_NONE
    for k in range(1, 5):
        if pi[OBST + k] == 0 and pi[MARK + k] < best:
            best = pi[MARK + k]
    val = pi[MARK]
    if best != MARK_NONE and best + 1 < val:
        val = best + 1
    return val
