"""`ant`: the pheromone baseline of the paper's section 5.5.

Returning ants drop pheromone on every cell they cross and head home by
compass (the direction of the base); the world diffuses and evaporates the
pheromone every tick.  Searching ants climb the pheromone: among the
neighbours that lead away from the base they move to the one with the most
pheromone, if it holds at least `threshold`; otherwise they walk at random.
Climbing only away from the base keeps them from following the trail to the
nest, where every trail converges (the grid analogue of the classic model's
"nest scent").  An ant whose compass directions are both blocked moves to a
random free neighbour and keeps walking at random for `detour` steps, which
gets it out of small pockets (with detour 0 ants freeze in cavities, as the
paper's Figure 11.a shows; deep cavities still hold them for long).

Params: params[P_THRESHOLD], params[P_DETOUR].  Diffusion, evaporation and the deposit amount
are properties of the world (world_server.grid.world).
"""

import numpy as np
from numba import njit

from agents.controllers.grid.foraging import read_load_outcome, seek_resource, unload_if_home
from agents.controllers.grid.moves import pick, random_free_dir, reset_action
from world_server.grid.face.layout import (
    A_DEPOSIT,
    A_MOVE,
    COMPASS_DC,
    COMPASS_DR,
    DIR_DC,
    DIR_DR,
    M_DETOUR,
    M_MODE,
    N_DIRS,
    OBST,
    P_DETOUR,
    P_THRESHOLD,
    PHER,
    RETURN,
)


@njit(cache=True, inline="always")
def toward_base(pi, d):
    dr = DIR_DR[d]
    dc = DIR_DC[d]
    return (dr != 0 and dr == pi[COMPASS_DR]) or (dc != 0 and dc == pi[COMPASS_DC])


@njit(cache=True, inline="always")
def compass_dir(pi, mem, params, seed, agent, tick):
    """Home by compass; when both compass directions are walled, detour."""
    if mem[M_DETOUR] > 0:
        mem[M_DETOUR] -= 1
        return random_free_dir(pi, seed, agent, tick, 5)
    m = 0
    for d in range(N_DIRS):
        if pi[OBST + 1 + d] == 0 and toward_base(pi, d):
            m |= 1 << d
    if m == 0:
        mem[M_DETOUR] = np.int64(params[P_DETOUR])
        return random_free_dir(pi, seed, agent, tick, 5)
    return pick(m, seed, agent, tick, 1)


@njit(cache=True, inline="always")
def climb_pheromone_dir(pi, pf, threshold, seed, agent, tick):
    """The free neighbour leading away from the base with the most pheromone
    (>= threshold), -1 if none qualifies."""
    m = 0
    best = threshold
    for d in range(N_DIRS):
        if pi[OBST + 1 + d] != 0 or toward_base(pi, d):
            continue
        p = pf[PHER + 1 + d]
        if p > best:
            best = p
            m = 0
        if p == best and p >= threshold:
            m |= 1 << d
    return pick(m, seed, agent, tick, 2)


@njit(cache=True, inline="always")
def ant_step(pi, pf, mem, act, params, seed, agent, tick):
    reset_action(act)
    read_load_outcome(pi, mem)
    if mem[M_MODE] == RETURN:
        if not unload_if_home(pi, mem, act):
            act[A_DEPOSIT] = 1
            act[A_MOVE] = compass_dir(pi, mem, params, seed, agent, tick)
            return
    if seek_resource(pi, mem, act, seed, agent, tick):
        return
    d = climb_pheromone_dir(pi, pf, params[P_THRESHOLD], seed, agent, tick)
    if d < 0:
        d = random_free_dir(pi, seed, agent, tick, 3)
    act[A_MOVE] = d
