"""Local moves shared by the grid controllers: update-value, descent, exploration.

Candidate neighbours are kept as 4-bit masks (bit d = direction d), so the
hot path allocates nothing.  Every choice among equals is uniform, drawn from
the counter-based generator (swarm.core.rng): a controller's decision depends only
on (seed, agent, tick).
"""

import numpy as np
from numba import njit

from swarm.core.rng import draw_below
from world_server.grid.face.layout import (
    A_DEPOSIT,
    A_LOAD,
    A_MARK,
    A_MOVE,
    A_TRAIL_ID,
    A_TRAIL_OP,
    A_UNLOAD,
    MARK,
    MARK_NONE,
    N_DIRS,
    OBST,
    STAY,
    TRAIL_KEEP,
)


@njit(cache=True, inline="always")
def reset_action(act):
    act[A_MOVE] = STAY
    act[A_MARK] = MARK_NONE
    act[A_TRAIL_OP] = TRAIL_KEEP
    act[A_TRAIL_ID] = 0
    act[A_LOAD] = 0
    act[A_UNLOAD] = 0
    act[A_DEPOSIT] = 0


@njit(cache=True, inline="always")
def pick(mask, seed, agent, tick, draw):
    """A uniform pick among the directions set in a 4-bit mask; -1 if empty."""
    n = (mask & 1) + ((mask >> 1) & 1) + ((mask >> 2) & 1) + ((mask >> 3) & 1)
    if n == 0:
        return np.int64(-1)
    k = np.int64(0) if n == 1 else draw_below(seed, agent, tick, draw, n)
    for d in range(N_DIRS):
        if (mask >> d) & 1:
            if k == 0:
                return np.int64(d)
            k -= 1
    return np.int64(-1)


@njit(cache=True, inline="always")
def free_mask(pi):
    m = 0
    for d in range(N_DIRS):
        if pi[OBST + 1 + d] == 0:
            m |= 1 << d
    return m


@njit(cache=True, inline="always")
def random_free_dir(pi, seed, agent, tick, draw):
    """A uniformly random non-obstacle neighbour, or STAY when boxed in."""
    d = pick(free_mask(pi), seed, agent, tick, draw)
    return STAY if d < 0 else d


@njit(cache=True, inline="always")
def explore_dir(pi, seed, agent, tick, draw):
    """Algorithm 2's move: a random unmarked neighbour if any, else any free one."""
    m = 0
    for d in range(N_DIRS):
        if pi[OBST + 1 + d] == 0 and pi[MARK + 1 + d] == MARK_NONE:
            m |= 1 << d
    if m == 0:
        return random_free_dir(pi, seed, agent, tick, draw)
    return pick(m, seed, agent, tick, draw)


@njit(cache=True, inline="always")
def descent_dir(pi, seed, agent, tick, draw):
    """RETURN TO BASE: the neighbour with the least mark (ties uniform)."""
    m = 0
    best = MARK_NONE
    for d in range(N_DIRS):
        if pi[OBST + 1 + d] != 0:
            continue
        v = pi[MARK + 1 + d]
        if v < best:
            best = v
            m = 0
        if v == best and v != MARK_NONE:
            m |= 1 << d
    if m == 0:
        return random_free_dir(pi, seed, agent, tick, draw)
    return pick(m, seed, agent, tick, draw)


@njit(cache=True, inline="always")
def extreme_dir_among(pi, layer, want, exclude, seed, agent, tick, draw, highest):
    """Among free neighbours whose `layer` value equals `want` (want < 0: any
    non-zero value) and that are not `exclude`, the one with the highest
    (or least) mark; -1 when there is none.  Used to climb and follow trails."""
    m = 0
    best = np.int64(0)
    for d in range(N_DIRS):
        if d == exclude or pi[OBST + 1 + d] != 0:
            continue
        v = pi[layer + 1 + d]
        if (want < 0 and v == 0) or (want >= 0 and v != want):
            continue
        mark = pi[MARK + 1 + d]
        if m == 0 or (mark > best if highest else mark < best):
            best = mark
            m = 0
        if mark == best:
            m |= 1 << d
    return pick(m, seed, agent, tick, draw)


@njit(cache=True, inline="always")
def resource_dir(pi, layer, seed, agent, tick, draw):
    """A neighbour holding resource (uniform among several), -1 if none."""
    m = 0
    for d in range(N_DIRS):
        if pi[OBST + 1 + d] == 0 and pi[layer + 1 + d] != 0:
            m |= 1 << d
    return pick(m, seed, agent, tick, draw)


@njit(cache=True, inline="always")
def opposite(d):
    return (d + 2) % N_DIRS
