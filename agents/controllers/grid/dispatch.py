"""Grid controllers and the one dispatch both engines call.

`step_controller(kind, ...)` is compiled once; the in-process engine calls it
in its loop over agents, and an agent process calls it through `answer_rows`
for the agents of one observation message, so there is exactly one
implementation of every controller's step.

The loops take the step as an argument (`rows_with(step, kind, ...)` calls
`step(kind, ...)`): the bundled entry points pass None, which stands for
`step_controller`, and are cached and built ahead of time; a user's controller (world_server.grid.face.own)
passes `own_step` with its own `@njit` step as the "kind", and numba compiles
the same loop once more around it.
"""

import numpy as np
from numba import njit, types
from numba.extending import overload

from agents.controllers.grid.ant import ant_step
from agents.controllers.grid.cmarking import cmarking_step
from agents.controllers.grid.marking import marking_step
from agents.controllers.grid.moves import reset_action
from world_server.grid.face.action import F_MARK, action_fault
from world_server.grid.face.layout import (
    A_DEPOSIT,
    A_LOAD,
    A_MARK,
    A_MODE,
    A_MOVE,
    A_TRAIL_ID,
    A_TRAIL_OP,
    A_UNLOAD,
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
from world_server.grid.face.marks import update_value
from world_server.grid.face.wire import OBS_INTS, OBS_PERCEPTION, R_ACT, R_AGENT, R_MARKED, R_MEM

FAULT_FIELD = np.array([A_MOVE, A_TRAIL_OP, A_TRAIL_ID, A_LOAD, A_UNLOAD, A_DEPOSIT, A_MODE, A_MARK], np.int64)


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


def call_step(step, kind, pi, pf, mem, act, params, seed, agent, tick):
    """`step(kind, ...)`, or the bundled `step_controller(kind, ...)` when `step` is None, chosen when
    numba compiles the caller (`_call_step`): a loop given None is the bundled loop, cached (passing
    the bundled dispatcher itself would embed its address and keep numba from caching the loop).
    The overload itself is not cached: its signature for a user's step holds numba Dispatcher types,
    whose pickled weak references die in the next process that loads the index and make numba's
    next save of that index raise ReferenceError.  A cached caller caches the bundled path anyway."""
    raise NotImplementedError("call_step runs in compiled code only")


@overload(call_step)
def _call_step(step, kind, pi, pf, mem, act, params, seed, agent, tick):
    if isinstance(step, types.NoneType):

        def bundled(step, kind, pi, pf, mem, act, params, seed, agent, tick):
            step_controller(kind, pi, pf, mem, act, params, seed, agent, tick)

        return bundled

    def given(step, kind, pi, pf, mem, act, params, seed, agent, tick):
        step(kind, pi, pf, mem, act, params, seed, agent, tick)

    return given


@njit
def own_step(user, pi, pf, mem, act, params, seed, agent, tick):
    """A user's step (`user`, a GridController's) on an action reset to "stay, write nothing"; an
    action the world would refuse raises ValueError("grid action", fault, value, agent, tick),
    which the runtimes turn into one line naming the controller (own.fault_line)."""
    reset_action(act)
    act[A_MODE] = 0
    user(pi, pf, mem, act, params, seed, agent, tick)
    fault = action_fault(act)
    if fault >= 0:
        raise ValueError("grid action", fault, act[FAULT_FIELD[fault]], agent, tick)
    if act[A_MARK] != MARK_NONE and act[A_MARK] < update_value(pi):
        raise ValueError("grid action", F_MARK, act[A_MARK], agent, tick)


@njit(cache=True)
def answer_rows(kind, ints_flat, pf_flat, mems, slot_of, out, params, seed, tick, null):
    """`rows_with` of the bundled controllers' step (cached, and built ahead of time)."""
    return rows_with(None, kind, ints_flat, pf_flat, mems, slot_of, out, params, seed, tick, null)


@njit
def rows_with(step, kind, ints_flat, pf_flat, mems, slot_of, out, params, seed, tick, null):
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
            call_step(step, kind, ints[i, OBS_PERCEPTION:], pf[i], mem, act, params, seed, agent, tick)
        row[R_AGENT] = agent
        value = act[A_MARK]
        row[R_MARKED] = 1 if value != MARK_NONE and value < ints[i, OBS_PERCEPTION + MARK] else 0
        row[R_MEM:] = mem
        n += 1
    return n
