"""`ant`: the pheromone baseline of the paper's section 5.5, NetLogo's Ants model on the grid.

Returning ants drop pheromone on every cell they cross and head home by
compass (the paper gives its ants the base's direction); the world diffuses
and evaporates the pheromone every tick.  Searching ants walk as in NetLogo's
Ants model (Wilensky 1997): each keeps a heading; when the pheromone on its
own cell lies in [threshold, ceiling) it sniffs ahead, ahead-left and
ahead-right and turns 45 degrees towards a side that smells stronger than
ahead ("uphill-chemical"); then it wiggles (its heading turns right by a
uniform 0..wiggle-1 degrees and left by another); if the cell ahead is blocked
it turns round (and takes a random free neighbour if that is blocked too);
then it moves one cell ahead.  On a 4-connected grid "ahead" is the neighbour
nearest the heading, and ahead-left/right the neighbours at -90/+90 degrees (a
robot perceiving its 4 neighbours has no diagonal cell to sniff).  Like the
c-marking agents, a searching ant moves into a resource it sees.

An ant whose compass directions are both blocked moves to a random free
neighbour and keeps walking at random for `detour` steps, which gets it out of
small pockets (with detour 0 ants freeze in cavities, as the paper's Figure
11.a shows).

Params: params[P_THRESHOLD], params[P_CEILING], params[P_WIGGLE], params[P_DETOUR].  Diffusion,
evaporation and the deposit amount are properties of the world (world_server.grid.world).
"""

import numpy as np
from numba import njit

from agents.controllers.grid.foraging import read_load_outcome, seek_resource, unload_if_home
from agents.controllers.grid.moves import pick, random_free_dir, reset_action
from swarm.core.rng import draw_below
from world_server.grid.face.layout import (
    A_DEPOSIT,
    A_MOVE,
    COMPASS_DC,
    COMPASS_DR,
    DIR_DC,
    DIR_DR,
    M_DETOUR,
    M_HEADING,
    M_MODE,
    N_DIRS,
    OBST,
    P_CEILING,
    P_DETOUR,
    P_THRESHOLD,
    P_WIGGLE,
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
def heading_dir(heading):
    """The neighbour (N, E, S, W) nearest a heading in degrees clockwise from north."""
    return np.int64(((heading + 45) % 360) // 90)


@njit(cache=True, inline="always")
def uphill_turn(pf, heading):
    """NetLogo's uphill-chemical: 45 degrees towards the stronger side when a side smells stronger than ahead."""
    ahead = pf[PHER + 1 + heading_dir(heading)]
    right = pf[PHER + 1 + heading_dir(heading + 90)]
    left = pf[PHER + 1 + heading_dir(heading + 270)]
    if right > ahead or left > ahead:
        return np.int64(45) if right > left else np.int64(315)
    return np.int64(0)


@njit(cache=True, inline="always")
def search_dir(pi, pf, mem, params, seed, agent, tick):
    """NetLogo's look-for-food, wiggle and `if not can-move? 1 [rt 180]`; the heading is kept in memory."""
    if mem[M_HEADING] == 0:  # first step: a random heading
        mem[M_HEADING] = 1 + draw_below(seed, agent, tick, 6, 360)
    heading = mem[M_HEADING] - 1
    if params[P_THRESHOLD] <= pf[PHER] < params[P_CEILING]:
        heading += uphill_turn(pf, heading)
    wiggle = np.int64(params[P_WIGGLE])
    if wiggle > 0:
        heading += draw_below(seed, agent, tick, 7, wiggle) - draw_below(seed, agent, tick, 8, wiggle)
    heading %= 360
    d = heading_dir(heading)
    if pi[OBST + 1 + d] != 0:
        heading = (heading + 180) % 360
        d = heading_dir(heading)
        if pi[OBST + 1 + d] != 0:
            d = random_free_dir(pi, seed, agent, tick, 3)
            if d < N_DIRS:
                heading = d * 90
    mem[M_HEADING] = heading + 1
    return d


@njit(cache=True)
def ant_step(pi, pf, mem, act, params, seed, agent, tick):
    reset_action(act)
    read_load_outcome(pi, mem)
    if mem[M_MODE] == RETURN:
        if not unload_if_home(pi, mem, act):
            act[A_DEPOSIT] = 1
            d = compass_dir(pi, mem, params, seed, agent, tick)
            act[A_MOVE] = d
            if d < N_DIRS:
                mem[M_HEADING] = d * 90 + 1
            return
        if mem[M_HEADING] > 0:  # NetLogo's return-to-nest: at the nest, turn round and head out again
            mem[M_HEADING] = (mem[M_HEADING] - 1 + 180) % 360 + 1
    if seek_resource(pi, mem, act, seed, agent, tick):
        return
    act[A_MOVE] = search_dir(pi, pf, mem, params, seed, agent, tick)
