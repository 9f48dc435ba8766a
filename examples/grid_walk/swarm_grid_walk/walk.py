"""`walk`: a correlated random walk forager on swarm's grid.

Searching, a robot keeps its heading with probability `persistence` and
otherwise turns to a random free neighbour; it steps into a resource it sees
and loads it.  Carrying, it heads home by compass, and when both compass
directions are walled it walks at random for `detour` steps.  It writes no
marks.  Every random choice is a counter-based draw of (seed, agent, tick), so
an agent process makes the in-process run's choices.
"""

import numpy as np
from numba import njit

from world_server.grid.face.layout import (
    A_LOAD,
    A_MODE,
    A_MOVE,
    A_UNLOAD,
    AT_BASE,
    CARRY,
    COMPASS_DC,
    COMPASS_DR,
    DIR_DC,
    DIR_DR,
    N_DIRS,
    OBST,
    RES,
    RETURN,
    SEARCH,
    STAY,
)
from world_server.grid.face.own import GridController, draw_below, draw_unit

# Its memory row: (name, words, start value).
MEMORY = (("heading", 1, -1), ("loading", 1), ("detour", 1))
HEADING, LOADING, DETOUR = 0, 1, 2
PERSISTENCE, DETOUR_STEPS = 0, 1  # its parameters, in the order `params` holds them


@njit(cache=True)
def pick_dir(options, seed, agent, tick, draw):
    """A uniform pick among the directions whose bit is set in `options`; STAY when none is."""
    count = 0
    for d in range(N_DIRS):
        count += (options >> d) & 1
    if count == 0:
        return STAY
    k = draw_below(seed, agent, tick, draw, count)
    d = 0
    while k > 0 or not (options >> d) & 1:
        k -= (options >> d) & 1
        d += 1
    return d


@njit(cache=True)
def free_options(pi):
    """The free neighbours, one bit a direction."""
    options = 0
    for d in range(N_DIRS):
        options |= (pi[OBST + 1 + d] == 0) << d
    return options


@njit(cache=True)
def home_options(pi):
    """The free neighbours towards the base (by compass), one bit a direction."""
    towards = 0
    for d in range(N_DIRS):
        towards |= (
            (DIR_DR[d] != 0 and DIR_DR[d] == pi[COMPASS_DR]) or (DIR_DC[d] != 0 and DIR_DC[d] == pi[COMPASS_DC])
        ) << d
    return towards & free_options(pi)


@njit(cache=True)
def home_dir(pi, mem, params, seed, agent, tick):
    """By compass; when both compass directions are walled, `detour` steps at random."""
    options = home_options(pi) if mem[DETOUR] == 0 else 0
    if mem[DETOUR] > 0:
        mem[DETOUR] -= 1
    elif options == 0:
        mem[DETOUR] = np.int64(params[DETOUR_STEPS])
    return pick_dir(options if options != 0 else free_options(pi), seed, agent, tick, 2)


@njit(cache=True)
def search_dir(pi, mem, params, seed, agent, tick):
    """Into a resource in view, else on along the heading (kept with probability `persistence`)."""
    for d in range(N_DIRS):
        if pi[OBST + 1 + d] == 0 and pi[RES + 1 + d] != 0:
            return d
    h = mem[HEADING]
    if h < 0 or pi[OBST + 1 + h] != 0 or draw_unit(seed, agent, tick, 0) >= params[PERSISTENCE]:
        h = pick_dir(free_options(pi), seed, agent, tick, 1)
    return h


@njit(cache=True)
def walk_step(pi, pf, mem, act, params, seed, agent, tick):
    """One tick of a walker: the action is given reset to "stay, write nothing"."""
    mem[LOADING] = 0
    if pi[CARRY] > 0:
        act[A_MODE] = RETURN
        if pi[AT_BASE] != 0:
            act[A_UNLOAD] = 1
            return
        act[A_MOVE] = home_dir(pi, mem, params, seed, agent, tick)
        return
    act[A_MODE] = SEARCH
    if pi[RES] != 0:
        act[A_LOAD] = 1
        mem[LOADING] = 1
        return
    d = search_dir(pi, mem, params, seed, agent, tick)
    act[A_MOVE] = d
    mem[HEADING] = d if d < N_DIRS else -1


WALK = GridController(
    step=walk_step,
    memory=MEMORY,
    parameters=(("persistence", 0.8), ("detour", 8.0)),
    description="a correlated random walk forager: a heading kept or turned at random, home by compass",
)
