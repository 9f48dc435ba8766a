"""Steps shared by every foraging controller: reading the outcome of a LOAD,
picking up resource, and dropping it at the base."""

from numba import njit

from agents.controllers.grid.moves import opposite, resource_dir
from world_server.grid.face.layout import (
    A_LOAD,
    A_MOVE,
    A_UNLOAD,
    AT_BASE,
    CARRY,
    M_CLIMBING,
    M_LOADING,
    M_MODE,
    M_PREV,
    RES,
    RETURN,
    SEARCH,
)


@njit(cache=True, inline="always")
def settle_mode(pi, mem):
    """Returning agents carry; searching agents do not.  After a restart the
    agent may find itself carrying in SEARCH mode: it then goes home."""
    if pi[CARRY] > 0 and mem[M_MODE] == SEARCH:
        mem[M_MODE] = RETURN


@njit(cache=True, inline="always")
def read_load_outcome(pi, mem):
    """Marking agents and ants: carrying after a LOAD means going home."""
    if mem[M_LOADING]:
        mem[M_LOADING] = 0
        mem[M_MODE] = RETURN if pi[CARRY] > 0 else SEARCH
    settle_mode(pi, mem)


@njit(cache=True, inline="always")
def unload_if_home(pi, mem, act):
    """At the base a returning agent drops its load and searches again in the
    same tick.  It keeps the memory of the cell it came from, so, as the
    paper's SEARCH & CLIMB TRAIL reads, it does not climb straight back up the
    trail it came down (docs/cmarking.md explains and measures this choice)."""
    if pi[AT_BASE] == 0:
        return False
    if pi[CARRY] > 0:
        act[A_UNLOAD] = 1
    mem[M_MODE] = SEARCH
    mem[M_CLIMBING] = 0
    return True


@njit(cache=True, inline="always")
def seek_resource(pi, mem, act, seed, agent, tick):
    """SEARCH's first rule.  On a resource cell: LOAD (the tick is spent
    loading, the outcome is read next tick).  Next to one: move into it.
    Returns True when the agent acted."""
    if pi[RES] != 0 and pi[CARRY] == 0:
        act[A_LOAD] = 1
        mem[M_LOADING] = 1
        mem[M_CLIMBING] = 0
        return True
    d = resource_dir(pi, RES, seed, agent, tick, 0)
    if d >= 0:
        act[A_MOVE] = d
        mem[M_PREV] = opposite(d)
        mem[M_CLIMBING] = 0
        return True
    return False
