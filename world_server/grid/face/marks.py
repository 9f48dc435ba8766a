"""The marking environment's one rule, shared by the world and the grid controllers.

A robot may lower the mark of the cell it stands on to UPDATE-VALUE and no
further (Algorithm 2 of Simonin et al. 2007): the controllers compute it to
write, and the world checks every write against it before applying it.  Its
numbers are MarkingRule's (world_server/grid/params.py), written here as literals.
"""

from numba import njit

from world_server.grid.face.layout import MARK, MARK_NONE, OBST


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
