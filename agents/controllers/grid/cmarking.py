"""`cmarking`: colour-marking agents, the paper's Algorithm 4.

SEARCH & CLIMB TRAIL, LOADING, RETURN & COLOUR TRAIL, RETURN & REMOVE TRAIL,
on top of Algorithm 2's exploration and UPDATE-VALUE.  The rules the paper
leaves open are fixed here and explained in docs/cmarking.md:

* a trail colour is a trail id, ((tick + 1) << 20) | (agent + 1), unique per
  trail and increasing with its creation time;
* LOADING on a coloured resource that is not exhausted returns home along the
  trail (RETURN_MEND): it steps to the least-valued cell of the trail's colour
  while that is lower than its own cell, otherwise descends the marks, and it
  colours every *uncoloured* cell it crosses with the trail's colour.  This is
  the paper's "algorithm equivalent to RETURN TO BASE", plus mending: a trail
  cut where a crossing trail was removed is joined up again on the next trip;
* an agent leaving the base after unloading does not climb back into the cell
  it came from (the paper's "different from the previous position");
* a remover follows and erases only its own colour; where its trail is broken
  it finishes the trip by plain descent;
* a climber that reaches the end of a trail with no resource in sight (and not
  next to the base) erases that dead fragment (mode ERASE);
* a climber that has climbed `climb_patience` steps without reaching a higher
  mark than it has already seen is circling: it erases the fragment it stands on.

Params: params[P_CLIMB_PATIENCE], params[P_DESCEND_ON_TRAIL], params[P_FORGET_AT_BASE] (rules 5 and 6 of
docs/cmarking.md; 0, 0: ours).
"""

from numba import njit

from agents.controllers.grid.foraging import seek_resource, settle_mode, unload_if_home
from agents.controllers.grid.moves import descent_dir, explore_dir, extreme_dir_among, opposite, reset_action
from world_server.grid.face.layout import (
    A_MARK,
    A_MOVE,
    A_TRAIL_ID,
    A_TRAIL_OP,
    AT_BASE,
    CARRY,
    ERASE,
    M_CLIMB_MAX,
    M_CLIMB_STALL,
    M_CLIMBING,
    M_LOADING,
    M_MODE,
    M_PREV,
    M_TRAIL,
    MARK,
    N_DIRS,
    OBST,
    P_CLIMB_PATIENCE,
    P_DESCEND_ON_TRAIL,
    P_FORGET_AT_BASE,
    RES,
    RETURN,
    RETURN_COLOUR,
    RETURN_MEND,
    RETURN_REMOVE,
    SEARCH,
    TRAIL,
    TRAIL_ERASE,
    TRAIL_PAINT,
)
from world_server.grid.face.marks import update_value


@njit(cache=True, inline="always")
def new_trail_id(tick, agent):
    return ((tick + 1) << 20) | (agent + 1)


@njit(cache=True, inline="always")
def begin_return(pi, mem, params, tick, agent):
    """LOADING, read one tick after the LOAD: choose the kind of return from
    what is left on the cell (the world resolved every agent's load)."""
    mem[M_LOADING] = 0
    mem[M_CLIMBING] = 0
    mem[M_PREV] = -1
    if pi[CARRY] == 0:
        mem[M_MODE] = SEARCH  # someone else emptied the cell first
    elif pi[RES] != 0:
        if pi[TRAIL] != 0:
            if params[P_DESCEND_ON_TRAIL] != 0:
                mem[M_MODE] = RETURN  # rule 5 read literally: plain descent, no colour
            else:
                mem[M_MODE] = RETURN_MEND  # already on a trail: follow it home, mending gaps
                mem[M_TRAIL] = pi[TRAIL]
        else:
            mem[M_MODE] = RETURN_COLOUR
            mem[M_TRAIL] = new_trail_id(tick, agent)
    elif pi[TRAIL] != 0:
        mem[M_MODE] = RETURN_REMOVE
        mem[M_TRAIL] = pi[TRAIL]
    else:
        mem[M_MODE] = RETURN


@njit(cache=True, inline="always")
def erase_step(pi, mem, act, seed, agent, tick):
    """Wipe colour mem[M_TRAIL] here and head for the least-valued neighbour of
    that colour; -1 when the colour goes no further."""
    colour = mem[M_TRAIL]
    if pi[TRAIL] == colour:
        act[A_TRAIL_OP] = TRAIL_ERASE
        act[A_TRAIL_ID] = colour
    return extreme_dir_among(pi, TRAIL, colour, -1, seed, agent, tick, 3, False)


@njit(cache=True, inline="always")
def next_to_base(pi):
    if pi[AT_BASE] != 0:
        return True
    for k in range(1, 5):
        if pi[OBST + k] == 0 and pi[MARK + k] == 0:
            return True
    return False


@njit(cache=True, inline="always")
def start_erasing(pi, mem, act, seed, agent, tick):
    """The trail under the agent leads nowhere (dead end, or a loop of trail
    cells): wipe this cell whatever touches it, which is what breaks a loop,
    then keep erasing that colour downhill (ERASE mode)."""
    colour = pi[TRAIL]
    mem[M_MODE] = ERASE
    mem[M_TRAIL] = colour
    mem[M_CLIMBING] = 0
    act[A_TRAIL_OP] = TRAIL_ERASE
    act[A_TRAIL_ID] = colour
    d = extreme_dir_among(pi, TRAIL, colour, -1, seed, agent, tick, 3, False)
    if d < 0:
        mem[M_MODE] = SEARCH
        d = explore_dir(pi, seed, agent, tick, 2)
    act[A_MOVE] = d
    mem[M_PREV] = opposite(d) if d < N_DIRS else -1


@njit(cache=True, inline="always")
def follow_erasing(pi, mem, act, seed, agent, tick):
    """One erasing step down the trail; False when the colour goes no further."""
    d = erase_step(pi, mem, act, seed, agent, tick)
    if d < 0:
        return False
    act[A_MOVE] = d
    mem[M_PREV] = opposite(d)
    return True


@njit(cache=True, inline="always")
def returning_step(pi, mem, act, params, seed, agent, tick):
    mode = mem[M_MODE]
    if mode == RETURN_REMOVE:
        if follow_erasing(pi, mem, act, seed, agent, tick):
            return
        mem[M_MODE] = RETURN  # trail broken: finish the trip by descent
    elif mode == RETURN_COLOUR or (mode == RETURN_MEND and pi[TRAIL] == 0):
        act[A_TRAIL_OP] = TRAIL_PAINT
        act[A_TRAIL_ID] = mem[M_TRAIL]
    if mode == RETURN_MEND:
        # Down the trail while it descends; every step lowers the mark, so the trip ends.
        d = extreme_dir_among(pi, TRAIL, mem[M_TRAIL], -1, seed, agent, tick, 6, False)
        if d >= 0 and pi[MARK + 1 + d] < act[A_MARK]:
            act[A_MOVE] = d
            mem[M_PREV] = opposite(d)
            return
    act[A_MOVE] = descent_dir(pi, seed, agent, tick, 1)
    if act[A_MOVE] < N_DIRS:
        mem[M_PREV] = opposite(act[A_MOVE])


@njit(cache=True, inline="always")
def search_step(pi, mem, act, params, seed, agent, tick):
    """SEARCH & CLIMB TRAIL."""
    if seek_resource(pi, mem, act, seed, agent, tick):
        return
    prev = mem[M_PREV]
    d = extreme_dir_among(pi, TRAIL, -1, prev, seed, agent, tick, 4, True)
    if d >= 0:
        m = pi[MARK + 1 + d]
        if mem[M_CLIMBING] == 0:
            mem[M_CLIMBING] = 1
            mem[M_CLIMB_MAX] = pi[MARK]
            mem[M_CLIMB_STALL] = 0
        if m > mem[M_CLIMB_MAX]:
            mem[M_CLIMB_MAX] = m
            mem[M_CLIMB_STALL] = 0
        else:
            mem[M_CLIMB_STALL] += 1
        if mem[M_CLIMB_STALL] > params[P_CLIMB_PATIENCE] and pi[TRAIL] != 0:
            start_erasing(pi, mem, act, seed, agent, tick)
            return
        act[A_MOVE] = d
        mem[M_PREV] = opposite(d)
        return
    if mem[M_CLIMBING] != 0 and pi[TRAIL] != 0 and not next_to_base(pi):
        start_erasing(pi, mem, act, seed, agent, tick)  # the trail leads nowhere
        return
    mem[M_CLIMBING] = 0
    d = explore_dir(pi, seed, agent, tick, 2)
    act[A_MOVE] = d
    mem[M_PREV] = opposite(d) if d < N_DIRS else -1


@njit(cache=True)
def cmarking_step(pi, pf, mem, act, params, seed, agent, tick):
    reset_action(act)
    act[A_MARK] = update_value(pi)
    if mem[M_LOADING]:
        begin_return(pi, mem, params, tick, agent)
    settle_mode(pi, mem)
    mode = mem[M_MODE]
    if mode == ERASE:
        if follow_erasing(pi, mem, act, seed, agent, tick):
            return
        mem[M_MODE] = SEARCH
        mem[M_PREV] = -1
    elif mode != SEARCH:
        if not unload_if_home(pi, mem, act):
            returning_step(pi, mem, act, params, seed, agent, tick)
            return
        if params[P_FORGET_AT_BASE] != 0:
            mem[M_PREV] = -1  # rule 6's alternative: climb from the base as if arriving fresh
    search_step(pi, mem, act, params, seed, agent, tick)
