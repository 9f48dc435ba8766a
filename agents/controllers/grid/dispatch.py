"""Grid controllers and the one dispatch both engines call.

`step_controller(kind, ...)` is compiled once; the in-process engine calls it
in its loop over agents, and an agent process calls it through `answer_rows`
for the agents of one observation message, so there is exactly one
implementation of every controller's step.
"""

import numpy as np
from numba import njit

from agents.controllers.grid.ant import ant_step
from agents.controllers.grid.cmarking import cmarking_step
from agents.controllers.grid.marking import marking_step
from world_server.grid.face.layout import (
    A_MARK,
    A_MODE,
    A_MOVE,
    ACT_LEN,
    BLOCKED,
    CMARKING,
    M_MODE,
    M_PREV,
    MARK,
    MARK_NONE,
    MARKING,
    PERC_F_LEN,
    STAY,
)
from world_server.grid.face.wire import OBS_INTS, OBS_PERCEPTION, R_ACT, R_AGENT, R_MARKED, R_MEM


@njit(cache=True)
def step_controller(kind, pi, pf, mem, act, params, seed, agent, tick):
    if pi[BLOCKED] != 0:
        # The last move did not happen: forget where we "came from" (a cell we never
        # left).  The climb goes on: a climber stuck on a trail keeps counting towards
        # its patience, so a crowd held on a trail that leads nowhere erases it and
        # disperses (resetting the climb here made 80 robots jam; docs/physics.md).
        mem[M_PREV] = -1
    if kind == CMARKING:
        cmarking_step(pi, pf, mem, act, params, seed, agent, tick)
    elif kind == MARKING:
        marking_step(pi, pf, mem, act, params, seed, agent, tick)
    else:
        ant_step(pi, pf, mem, act, params, seed, agent, tick)
    act[A_MODE] = mem[M_MODE]  # reported for the recording


@njit(cache=True)
def answer_rows(kind, ints_flat, pf_flat, mems, slot_of, out, params, seed, tick, null):
    """An agent process's whole answer to one observation message, in one call.

    `ints_flat` / `pf_flat` are the message's blocks as they came (read-only,
    unchecked): K rows of agent, cell, integer perception (world_server.grid.face.wire.OBS_INTS)
    and K rows of float perception.  `slot_of[agent]` is the agent's memory row in
    `mems` (-1, or an id past the table: not ours, skipped).  Writes one action row
    per agent stepped (world_server.grid.face.wire.ACT_ROW: agent, action, whether its mark
    write lowers its cell's mark, memory) and returns how many, or -1 when the
    blocks disagree or hold a value that is not finite.  `null`: the benchmark
    floor, every agent answers STAY without running its controller."""
    if ints_flat.size % OBS_INTS or pf_flat.size != ints_flat.size // OBS_INTS * PERC_F_LEN:
        return -1
    for j in range(pf_flat.size):
        if not np.isfinite(pf_flat[j]):
            return -1
    k = ints_flat.size // OBS_INTS
    ints = ints_flat.reshape((k, OBS_INTS))
    pf = pf_flat.reshape((k, PERC_F_LEN))
    n = 0
    for i in range(k):
        agent = ints[i, 0]
        if agent < 0 or agent >= len(slot_of) or slot_of[agent] < 0 or n >= out.shape[0]:
            continue
        mem = mems[slot_of[agent]]
        row = out[n]
        act = row[R_ACT : R_ACT + ACT_LEN]
        act[:] = 0
        if null:
            act[A_MOVE] = STAY
        else:
            step_controller(kind, ints[i, OBS_PERCEPTION:], pf[i], mem, act, params, seed, agent, tick)
        row[R_AGENT] = agent
        value = act[A_MARK]
        row[R_MARKED] = 1 if value != MARK_NONE and value < ints[i, OBS_PERCEPTION + MARK] else 0
        row[R_MEM:] = mem
        n += 1
    return n
