"""The grid world's side of the wire, compiled: observation rows out, action rows in.

The lock-step tick's cost is per message, and at one agent per process there
are a hundred messages each way per tick: the world fills every active
agent's observation row in one call, and checks and applies a whole action
message in one call, rather than a Python loop over agents and fields.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from swarm.core.wire import MAX_MESSAGE_BYTES
from world_server.grid.face.action import action_fault
from world_server.grid.face.layout import (
    A_MARK,
    ACT_LEN,
    MARK_NONE,
    MEM_LEN,
    PERC_F_LEN,
)
from world_server.grid.face.marks import update_value
from world_server.grid.face.wire import ACT_ROW, NOT_PLAIN, OBS_INTS, OBS_PERCEPTION, R_ACT, R_AGENT, R_MARKED, R_MEM
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
from world_server.grid.world import perceive

ACTIVE = 2  # world_server.server.ACTIVE (a slot whose agent is in the run)

# Why an action row was refused (index into the counts `accept_rows` returns).
REFUSALS = ("act: unknown agent", "act: names an agent of another process", "act: second action in one tick",
            "act: out-of-range action", "act: a mark lower than UPDATE-VALUE allows")  # fmt: skip
UNKNOWN, FOREIGN, SECOND, OUT_OF_RANGE, LOW_MARK = range(5)


@njit(cache=True)
def mark_floors(ints, agents, floors):
    """floors[agents[i]]: the lowest mark the agent of observation row i may
    write on its cell this tick, against which its action row's mark is
    checked: UPDATE-VALUE (`face.marks.update_value`, the controllers' own) on the
    perception the world has just sent it."""
    for i in range(len(agents)):
        floors[agents[i]] = update_value(ints[i, OBS_PERCEPTION:])


@njit(cache=True)
def observe_rows(layers, pher, pher_on, base_r, base_c, pos, payload, blocked, agents, ints, pf, null):
    """Row i of `ints` / `pf`: agent `agents[i]`, its cell, its perception
    (left zero in the benchmark's null world)."""
    width = layers.shape[2]
    for i in range(len(agents)):
        a = agents[i]
        r, c = pos[a, 0], pos[a, 1]
        ints[i, 0] = a
        ints[i, 1] = r * width + c
        if not null:
            perceive(layers, pher, pher_on, base_r, base_c, r, c, payload[a], blocked[a], ints[i, 2:], pf[i])


OBS_OVERHEAD = 64  # bytes of an observation message besides its blocks (at most)


@njit(cache=True)
def write_observations(tick, ints, pf, bounds, out, offsets):
    """Every agent process's observation message, byte for byte as
    `world_server.grid.face.wire.observations` packs it, one after another in `out`:
    process g's rows are bounds[g] .. bounds[g + 1] of `ints` and `pf` (both
    C-contiguous), its message out[offsets[g]:offsets[g + 1]].  Returns the
    end.  `out` holds OBS_OVERHEAD bytes a process besides the blocks."""
    ibits, fbits = ints.reshape(-1).view(np.uint64), pf.reshape(-1).view(np.uint64)
    ni, nf = ints.shape[1], pf.shape[1]
    at = 0
    for g in range(len(bounds) - 1):
        offsets[g] = at
        first, rows = bounds[g], bounds[g + 1] - bounds[g]
        at = write_raw(out, at, OBS_HEAD)
        at = write_uint(out, at, tick)
        at = write_key(out, at, INTS_KEY)
        at = write_tagged(out, at, rows * ni * 8, 0xC4, 3)  # bin 8, 16, 32
        at = write_words(out, at, ibits, first * ni, rows * ni)
        at = write_key(out, at, PF_KEY)
        at = write_tagged(out, at, rows * nf * 8, 0xC4, 3)
        at = write_words(out, at, fbits, first * nf, rows * nf)
    offsets[len(bounds) - 1] = at
    return at


@njit(cache=True, inline="always")
def _valid(row) -> bool:
    if action_fault(row[R_ACT : R_ACT + ACT_LEN]) >= 0:
        return False
    return row[R_MARKED] == 0 or row[R_MARKED] == 1


@njit(cache=True)
def accept_rows(rows, slots, group_ids, group, lockstep, acted, acts, mark_floor, memory):
    """Check every row of one action message from process `group` and apply
    those that pass; returns the refusals counted by reason (REFUSALS).  A
    refused row changes nothing."""
    refused = np.zeros(len(REFUSALS), dtype=np.int64)
    _accept(rows, slots, group_ids, group, lockstep, acted, acts, mark_floor, memory, refused)
    return refused


@njit(cache=True)
def _accept(rows, slots, group_ids, group, lockstep, acted, acts, mark_floor, memory, refused):
    """Rows accepted; each refusal added to its reason's count in `refused`."""
    n = len(slots)
    accepted = 0
    for i in range(rows.shape[0]):
        row = rows[i]
        a = row[R_AGENT]
        if a < 0 or a >= n or slots[a] != ACTIVE:
            refused[UNKNOWN] += 1
        elif group_ids[a] != group:
            refused[FOREIGN] += 1
        elif lockstep and acted[a]:  # in real time the latest action wins
            refused[SECOND] += 1
        elif not _valid(row):
            refused[OUT_OF_RANGE] += 1
        elif row[R_ACT + A_MARK] != MARK_NONE and row[R_ACT + A_MARK] < mark_floor[a]:
            refused[LOW_MARK] += 1
        else:  # the mark write rides the row and is applied with the tick (min-merged, as in-process)
            for k in range(ACT_LEN):
                acts[a, k] = row[R_ACT + k]
            for k in range(MEM_LEN):
                memory[a, k] = row[R_MEM + k]
            acted[a] = True
            accepted += 1
    return accepted


@njit(cache=True)
def accept_message(buf, first_tick, last_tick, slots, group_ids, group, lockstep, acted, acts, mark_floor, memory,
                   refused):  # fmt: skip
    """An action message from process `group`, read where its bytes lie (laid
    out as `world_server.grid.face.wire.pack_actions` packs it) and applied as `accept_rows`
    applies its rows, in one call.  Returns how many rows were accepted (each
    refused one is added to its reason's count in `refused`, which the caller
    reads once a tick), or NOT_PLAIN, having applied nothing: a tick outside
    first_tick .. last_tick, any other layout, anything malformed, which the
    Python path then counts and says why it refuses."""
    n = len(buf)
    if n > MAX_MESSAGE_BYTES:
        return NOT_PLAIN
    tick, at = read_head(buf, ACT_HEAD)
    if at < 0:
        return NOT_PLAIN
    at = key(buf, at, ROWS_KEY)
    if at < 0:
        return NOT_PLAIN
    rows_at, rows_len = read_bin(buf, at)
    if rows_at < 0 or rows_at + rows_len != n or rows_len % (ACT_ROW * 8):
        return NOT_PLAIN
    if not first_tick <= tick <= last_tick:
        return NOT_PLAIN
    count = rows_len // (ACT_ROW * 8)
    rows = words(buf, rows_at, count * ACT_ROW).view(np.int64).reshape((count, ACT_ROW))
    return _accept(rows, slots, group_ids, group, lockstep, acted, acts, mark_floor, memory, refused)


@njit(cache=True)
def accept_messages(buf, starts, groups, first_tick, last_tick, slots, group_ids, lockstep, acted, acts, mark_floor,
                    memory, refused, status):  # fmt: skip
    """`accept_message` for each message of buf[starts[m]:starts[m + 1]] from
    process `groups[m]`, in order: one call for all that came since the last,
    so the world does not enter compiled code once per message.  status[m]:
    its rows accepted, or NOT_PLAIN.  Returns the rows accepted."""
    total = 0
    for m in range(len(groups)):
        status[m] = accept_message(buf[starts[m]:starts[m + 1]], first_tick, last_tick, slots, group_ids, groups[m],
                                   lockstep, acted, acts, mark_floor, memory, refused)  # fmt: skip
        if status[m] != NOT_PLAIN:
            total += status[m]
    return total


def warm_up(world) -> None:
    """Load every kernel now (no agents, no rows), so the first tick does not compile."""
    none, ints, pf = np.zeros(0, np.int64), np.zeros((0, OBS_INTS), np.int64), np.zeros((0, PERC_F_LEN))
    observe_rows(world.layers, world.pher, world.pheromone_on, world.base[0], world.base[1], world.pos,
                 world.payload, world.blocked, none, ints, pf, False)  # fmt: skip
    n = len(world.pos)
    mark_floors(ints, none, np.zeros(n, np.int64))
    accept_rows(np.zeros((0, ACT_ROW), np.int64), np.zeros(n, np.int64), np.zeros(n, np.int64), 0, True,
                np.zeros(n, bool), world.acts, np.zeros(n, np.int64), np.zeros((n, MEM_LEN), np.int64))  # fmt: skip
    accept_messages(np.zeros(0, np.uint8), np.zeros(1, np.int64), none, 0, 0, np.zeros(n, np.int64),
                    np.zeros(n, np.int64), True, np.zeros(n, bool), world.acts, np.zeros(n, np.int64),
                    np.zeros((n, MEM_LEN), np.int64), np.zeros(len(REFUSALS), np.int64), none)  # fmt: skip
    write_observations(0, ints, pf, np.zeros(1, np.int64), np.zeros(0, np.uint8), np.zeros(1, np.int64))
