"""A grid agent process's answer to one observation, envelope included, in one
compiled call.

The world packs every observation the same way (`world_server.grid.face.wire.observations`:
a msgpack map of v, type, tick, ints, pf, in that order), so the agent reads
those bytes where they stand instead of unpacking a dict, steps its agents
(`dispatch.answer_rows`), and writes the action message's msgpack bytes as
`world_server.grid.face.wire.pack_actions` would (tests hold the two byte for byte).  Any
other message - a stop, a resumed run's memory, a wake, anything malformed -
is left to the Python parser, which says what it is or why it is refused.
Every read is bounds-checked: a short or lying buffer is NOT_PLAIN, never a
read past its end.
"""

from functools import partial

import numpy as np
from numba import njit

from agents.controllers.grid.dispatch import answer_rows, own_step, rows_with, step_controller
from world_server.grid.face.layout import MARKING, N_PARAMS, new_action, new_memory, new_perception
from world_server.grid.face.wire import ACT_ROW, ENVELOPE, NOT_PLAIN, OBS_INTS, R_MARKED, observations
from world_server.grid.face.wire_bytes import (
    ACT_HEAD,
    INTS_KEY,
    OBS_HEAD,
    PF_KEY,
    ROWS_KEY,
    key,
    read_bin,
    read_head,
    words,
    write_key,
    write_raw,
    write_tagged,
    write_uint,
    write_words,
)


@njit(cache=True)
def answer_message(kind, buf, mems, slot_of, rows, params, seed, null, out, info):
    """`message_with` of the bundled controllers' step (cached, and built ahead of time)."""
    return message_with(None, kind, buf, mems, slot_of, rows, params, seed, null, out, info)


@njit
def message_with(step, kind, buf, mems, slot_of, rows, params, seed, null, out, info):
    """Answer the observation in `buf` (its `bytes`, or a uint8 array) into `out` (the action message's bytes);
    returns their length, -1 for an observation whose blocks are malformed (not
    answered, as `answer_rows` says), or NOT_PLAIN.  `info`: rows written,
    whether any row put a mark write, the tick."""
    n = len(buf)
    tick, at = read_head(buf, OBS_HEAD)
    if at < 0:
        return NOT_PLAIN
    at = key(buf, at, INTS_KEY)
    if at < 0:
        return NOT_PLAIN
    ints_at, ints_len = read_bin(buf, at)
    if ints_at < 0:
        return NOT_PLAIN
    at = key(buf, ints_at + ints_len, PF_KEY)
    if at < 0:
        return NOT_PLAIN
    pf_at, pf_len = read_bin(buf, at)
    if pf_at < 0 or pf_at + pf_len != n:
        return NOT_PLAIN
    if ints_len % 8 or pf_len % 8:
        return -1
    ints = words(buf, ints_at, ints_len // 8).view(np.int64)
    pf = words(buf, pf_at, pf_len // 8).view(np.float64)
    got = rows_with(step, kind, ints, pf, mems, slot_of, rows, params, seed, tick, null)
    if got < 0:
        return -1
    marked = 0
    for i in range(got):
        marked |= rows[i, R_MARKED]
    info[0], info[1], info[2] = got, marked, tick
    size = got * ACT_ROW * 8
    if len(out) < ENVELOPE + size:
        return -1
    at = write_raw(out, 0, ACT_HEAD)
    at = write_uint(out, at, tick)
    at = write_key(out, at, ROWS_KEY)
    at = write_tagged(out, at, size, 0xC4, 3)  # bin 8, 16, 32
    return write_words(out, at, rows.reshape(-1).view(np.uint64), 0, got * ACT_ROW)


def warm_up(user=None) -> None:
    """Compile, or load from the cache, the step kernel now: an agent's first
    observation must not wait for it (lock-step deadlines are short).  `user`: a
    user's step (world_server.grid.face.own.GridController.step), compiled into
    the same loops instead of the bundled ones, and not run (null: every agent
    stays), since a made-up perception is no tick of a run."""
    if user is None:
        step, kind, rows, message, null = step_controller, MARKING, answer_rows, answer_message, False
    else:
        step, kind, null = None, user, True
        rows, message = partial(rows_with, own_step), partial(message_with, own_step)
    pi, pf = new_perception()
    if step is not None:
        step(kind, pi, pf, new_memory(1)[0], new_action(), np.zeros(N_PARAMS), np.int64(0), 0, 0)
    ints = np.frombuffer(np.zeros(OBS_INTS, np.int64).tobytes(), np.int64)  # read-only, as a message's block
    out = np.zeros((1, ACT_ROW), np.int64)
    rows(kind, ints, np.frombuffer(pf.tobytes(), np.float64), new_memory(1), np.zeros(1, np.int64), out,
         np.zeros(N_PARAMS), np.int64(0), np.int64(0), null)  # fmt: skip
    observation = observations(0, np.zeros((1, OBS_INTS), np.int64), pf[None])  # bytes, as the runtime passes them
    message(kind, observation, new_memory(1), np.zeros(1, np.int64), out, np.zeros(N_PARAMS), np.int64(0), null,
            np.zeros(ENVELOPE + ACT_ROW * 8, np.uint8), np.zeros(3, np.int64))  # fmt: skip
