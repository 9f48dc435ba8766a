"""The arena family of the wire protocol (keys and framing: world_server/grid/face/wire.py).

    obs/<group>   world -> agent process: for one tick, every agent's sensor
                  readings, each array as [dtype, shape, little-endian bytes]
    act/<group>   agent process -> world: their wheel speeds (K x 2 float64, m/s), and what
                  their controllers publish to a shared key space this tick (`shared`:
                  [agent, share, msgpack payload], opaque to the world); the world puts each
                  on <share>/<agent> and hands them to every agent process with the next
                  tick's observations (`shared` there too), so in lock-step every robot reads
                  tick t's writes at tick t + 1, as in the in-process engine
                  and what their robots broadcast to their range-and-bearing neighbours
                  (`rab`: [agent, bytes], at most MAX_PAYLOAD each), heard from the next tick on,
                  and, while the world records, the agents whose record() for this tick went
                  out on records/<group> before it (`records`: [agent]; the world awaits those
                  at the run's end)
                  At the ticks after which the world saves its state (`keep` in the
                  observation), the action also carries each controller's memory
                  (`memory`: [agent, bytes of swarm.core.memory_codec]); the world stores it
                  and hands it back, as a `memory` message on obs/<group> or in a
                  newcomer's welcome, when a restarted world resumes the run
    plans/<group> agent process -> world: one agent's planned path (P x 2 float64, m), once
                  per new plan, at most MAX_PLAN_POINTS points (the recording's, not the controller's)
    records/<group> agent process -> world, only while the world records: one agent's
                  `record()` (swarm.core.memory_codec bytes of its numbers and numeric arrays;
                  the arrays every ARRAYS_EVERY ticks, as the recording shows them), for a
                  controller whose registry entry names no log of its own (a user's)

Decoding never raises on bad input: it returns a `Rejected` reason.  Wheel
speeds are not judged here: the world checks every agent's pair (finite,
within its robot's limits) and counts what it refuses by reason.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import msgpack
import numpy as np

from swarm.core import memory_codec
from swarm.core.wire import (
    FAMILY_ARENA,
    HEADERS,
    MAX_MESSAGE_BYTES,
    HandBack,
    Rejected,
    bin_header,
    check_family,
    family_header,
    first_rejection,
    int_field,
    int_list,
    pack,
    pack_ending_with,
    unpack,
)
from world_server.arena.face.sensors.range_bearing import MAX_PAYLOAD

MAX_OBS_BYTES = 64 * 1024 * 1024  # observations come from the world; 100 animats take ~100 KB
MAX_ACT_BYTES = 64 * 1024 * 1024  # an action may carry shared maps and, at a save, the controllers' memory
DTYPES = {"<f8": np.float64, "<i8": np.int64, "|u1": np.uint8, "|b1": np.bool_}
ITEMSIZE = {kind: np.dtype(kind).itemsize for kind in DTYPES}
MAX_SENSORS, MAX_DIMS = 32, 4
MAX_PLAN_POINTS = 2000  # 32 KB: a plan message stays under the world's message limit
MAX_RECORD_BYTES = 1024 * 1024  # one record() message: a user's numbers and a few small arrays
ARRAYS_EVERY = 10  # ticks between the arrays of a record() sent (swarm.recording.records shows them as often)


MAX_SHARED = 4 * 1024 * 1024  # bytes of shared payloads in one message
Shared = list[tuple[int, str, bytes]]  # (agent, share, payload)
Memories = list[tuple[int, bytes | memoryview]]  # (agent, its controller's memory, swarm.core.memory_codec)
Broadcasts = list[tuple[int, bytes]]  # (agent, what its robot broadcasts: sensors/range_bearing.py)
MemoryPieces = list[tuple[int, list]]  # (agent, its memory as swarm.core.memory_codec.pieces): sent without a blob


@dataclass(frozen=True)
class ArenaObs:
    tick: int
    agents: np.ndarray  # (K,)
    perceptions: list[dict[str, np.ndarray]]
    shared: Shared = ()  # what every robot published last tick
    keep: bool = False  # the world saves after this tick: send the controllers' memory with the action


@dataclass(frozen=True)
class ArenaActs:
    tick: int
    agents: np.ndarray  # (K,)
    wheels: np.ndarray  # (K, 2), or (K, 3) with acts; not yet judged
    shared: Shared = ()  # what these agents publish this tick, not yet judged
    memory: Memories = ()  # at a save: each controller's memory after this tick's step
    rab: Broadcasts = ()  # what these agents' robots broadcast this tick, not yet judged
    records: tuple[int, ...] = ()  # the agents whose record() for this tick was sent before this message


@dataclass(frozen=True)
class ArenaMemory(HandBack):
    """A resumed run, before its first tick: each agent's controller memory at the saved tick."""

    memory: Memories


def _memory_field(memory: Memories) -> list:
    return [[int(a), bytes(blob)] for a, blob in memory]


def parse_memory(raw, agents: np.ndarray | None = None) -> Memories | Rejected:
    """[[agent, bytes], ...]; with `agents`, only those agents may appear (an action's)."""
    if raw is None:
        return []
    if not isinstance(raw, list):
        return Rejected("memory: expected a list of [agent, bytes]")
    named = None if agents is None else set(agents.tolist())
    out = []
    for item in raw:
        if not (
            isinstance(item, list)
            and len(item) == 2
            and type(item[0]) is int
            and isinstance(item[1], bytes | memoryview)
        ):  # a view where the message was read with views
            return Rejected("memory: expected [agent, bytes]")
        if named is not None and item[0] not in named:
            return Rejected("memory: names an agent the message does not act for")
        out.append((item[0], item[1]))
    return out


_MEMORY_HEAD = pack({"type": "memory", "family": FAMILY_ARENA})[1:]  # how memory_message's map begins


def memory_message(memory: Memories) -> bytes:
    return pack({"type": "memory", "family": FAMILY_ARENA, "memory": _memory_field(memory)})


def _shared_field(shared: Shared) -> list:
    return [[int(a), str(s), bytes(p)] for a, s, p in shared]


def parse_shared(raw) -> Shared | Rejected:
    if raw is None:
        return []
    if not isinstance(raw, list):
        return Rejected("shared: expected a list of [agent, share, bytes]")
    out, total = [], 0
    for item in raw:
        if not (isinstance(item, list) and len(item) == 3 and isinstance(item[0], int) and not isinstance(item[0], bool)
                and isinstance(item[1], str) and isinstance(item[2], bytes)):  # fmt: skip
            return Rejected("shared: expected [agent, share, bytes]")
        total += len(item[2])
        if total > MAX_SHARED:
            return Rejected(f"shared: more than {MAX_SHARED} bytes")
        out.append((item[0], item[1], item[2]))
    return out


def parse_rab(raw, agents: np.ndarray) -> Broadcasts | Rejected:
    """[[agent, bytes], ...], only of the agents the action is for."""
    if raw is None:
        return []
    if not isinstance(raw, list):
        return Rejected("rab: expected a list of [agent, bytes]")
    named, out = set(agents.tolist()), []
    for item in raw:
        if not (isinstance(item, list) and len(item) == 2 and type(item[0]) is int and isinstance(item[1], bytes)
                and len(item[1]) <= MAX_PAYLOAD):  # fmt: skip
            return Rejected(f"rab: expected [agent, at most {MAX_PAYLOAD} bytes]")
        if item[0] not in named:
            return Rejected("rab: names an agent the message does not act for")
        out.append((item[0], item[1]))
    return out


def _encode(value) -> list:
    a = np.asarray(value)
    kind = {np.dtype(np.float64): "<f8", np.dtype(np.int64): "<i8", np.dtype(np.uint8): "|u1",
            np.dtype(np.bool_): "|b1"}.get(a.dtype)  # fmt: skip
    if kind is None:
        a, kind = a.astype(np.float64), "<f8"
    return [kind, list(a.shape), np.ascontiguousarray(a, dtype=DTYPES[kind]).astype(kind).tobytes()]


def observations(tick: int, agents, perceptions: list[dict[str, np.ndarray]], shared: Shared = (),
                 keep: bool = False) -> bytes:  # fmt: skip
    m = {"type": "obs", "family": FAMILY_ARENA, "tick": tick, "agents": [int(a) for a in agents],
         "perceptions": [{k: _encode(v) for k, v in p.items()} for p in perceptions]}  # fmt: skip
    if shared:
        m["shared"] = _shared_field(shared)
    if keep:
        m["keep"] = True
    return pack(m)


def actions(tick: int, agents, wheels: np.ndarray, shared: Shared = (), memory: Memories | MemoryPieces = (),
            rab: Broadcasts = (), records: Sequence[int] = ()) -> bytes:  # fmt: skip
    """(K, 2) wheel speeds, or (K, 3) with a consummatory act each: the acts go
    in their own field, and only when one is not 0 (the message of robots
    without a metabolism stays as it was); so do broadcasts, only when there are,
    and the agents whose record() for this tick went out before it (the world
    waits for those at the run's end).  Memory given as pieces is written into
    the message once (the same bytes as its blob would give)."""
    wheels = np.asarray(wheels, np.float64).reshape(len(agents), -1)
    m = {"type": "act", "family": FAMILY_ARENA, "tick": tick, "agents": [int(a) for a in agents],
         "wheels": np.ascontiguousarray(wheels[:, :2]).astype("<f8").tobytes()}  # fmt: skip
    if wheels.shape[1] > 2 and np.any(wheels[:, 2] != 0):
        m["acts"] = np.ascontiguousarray(wheels[:, 2]).astype("<f8").tobytes()
    if shared:
        m["shared"] = _shared_field(shared)
    if rab:
        m["rab"] = [[int(a), bytes(b)] for a, b in rab]
    if records:
        m["records"] = [int(a) for a in records]
    if memory:
        return pack_ending_with(m, "memory", _memory_pieces(memory))
    return pack(m)


def _memory_pieces(memory: Memories | MemoryPieces) -> list:
    """The memory field's msgpack form, [[agent, bin], ...], each bin written from its pieces."""
    out = [HEADERS.pack_array_header(len(memory))]
    for agent, blob in memory:
        parts = [blob] if isinstance(blob, bytes | bytearray) else blob
        size = sum(memoryview(p).nbytes for p in parts)
        out += [HEADERS.pack_array_header(2) + msgpack.packb(int(agent)) + bin_header(size), *parts]
    return out


def _decode(entry) -> np.ndarray | Rejected:
    if not (isinstance(entry, list) and len(entry) == 3 and isinstance(entry[0], str) and entry[0] in DTYPES
            and isinstance(entry[2], bytes)):  # fmt: skip
        return Rejected("perception: expected [dtype, shape, bytes]")
    kind, shape, raw = entry
    if not (isinstance(shape, list) and len(shape) <= MAX_DIMS
            and all(isinstance(n, int) and not isinstance(n, bool) and 0 <= n <= 1 << 20 for n in shape)):  # fmt: skip
        return Rejected("perception: bad shape")
    if math.prod(shape) * ITEMSIZE[kind] != len(raw):  # plain ints: a numpy reduction per reading cost more
        return Rejected("perception: shape and bytes disagree")
    return np.frombuffer(raw, dtype=kind).reshape(shape).astype(DTYPES[kind])


def parse_obs(data: bytes) -> ArenaObs | Rejected | dict:
    """A batch of readings, the memories a resumed world hands back, or the raw dict of a `stop` message.
    A memory message as `memory_message` writes it is read with its blobs as views of `data`: a DFT
    robot's is MBs, and the agent must not hold it twice (an agent process's 80 MB budget)."""
    m = unpack(data, MAX_OBS_BYTES, views=data.startswith(_MEMORY_HEAD, 1))  # after the map's header byte
    if isinstance(m, Rejected) or m.get("type") in ("stop", "wake"):
        return m
    if m.get("type") == "memory":
        memory = parse_memory(m.get("memory"))
        return memory if isinstance(memory, Rejected) else ArenaMemory(memory)
    m = check_family(m, "obs", FAMILY_ARENA, "an arena observation")
    if isinstance(m, Rejected):
        return m
    tick, agents = int_field(m, "tick"), int_list(m, "agents")
    if bad := first_rejection(tick, agents):
        return bad
    raw = m.get("perceptions")
    if not isinstance(raw, list) or len(raw) != len(agents):
        return Rejected("perceptions: one per agent")
    perceptions = []
    for p in raw:
        if not isinstance(p, dict) or len(p) > MAX_SENSORS or not all(isinstance(k, str) for k in p):
            return Rejected("perceptions: expected a map of sensor readings")
        decoded = {k: _decode(v) for k, v in p.items()}
        if bad := first_rejection(*decoded.values()):
            return bad
        perceptions.append(decoded)
    if bad := first_rejection(shared := parse_shared(m.get("shared"))):
        return bad
    return ArenaObs(tick, agents, perceptions, shared, m.get("keep") is True)


def parse_acts(data: bytes) -> ArenaActs | Rejected:
    header = family_header(data, "act", FAMILY_ARENA, "an action", MAX_ACT_BYTES)
    if isinstance(header, Rejected):
        return header
    m, tick = header
    agents = int_list(m, "agents")
    if isinstance(agents, Rejected):
        return agents
    raw = m.get("wheels")
    if not isinstance(raw, bytes) or len(raw) != 16 * len(agents):
        return Rejected("wheels: expected 2 binary float64 per agent")  # no count: reasons are a fixed few
    if bad := first_rejection(shared := parse_shared(m.get("shared"))):
        return bad
    wheels = np.frombuffer(raw, dtype="<f8").reshape(len(agents), 2).astype(np.float64)
    if "acts" in m:
        acts = m["acts"]
        if not isinstance(acts, bytes) or len(acts) != 8 * len(agents):
            return Rejected("acts: expected 1 binary float64 per agent")
        wheels = np.column_stack([wheels, np.frombuffer(acts, dtype="<f8").astype(np.float64)])
    if bad := first_rejection(memory := parse_memory(m.get("memory"), agents), rab := parse_rab(m.get("rab"), agents)):
        return bad
    records = int_list(m, "records") if "records" in m else np.zeros(0, np.int64)
    if isinstance(records, Rejected):
        return records
    return ArenaActs(tick, agents, wheels, shared, memory, rab, tuple(records.tolist()))


@dataclass(frozen=True)
class Plan:
    tick: int
    agent: int
    path: np.ndarray  # (P, 2)


def plan_message(tick: int, agent: int, path: np.ndarray) -> bytes:
    """A planned path thinned to at most MAX_PLAN_POINTS points (ends kept)."""
    path = np.asarray(path, np.float64).reshape(-1, 2)
    if len(path) > MAX_PLAN_POINTS:
        path = path[np.linspace(0, len(path) - 1, MAX_PLAN_POINTS).round().astype(int)]
    return pack({"type": "plan", "family": FAMILY_ARENA, "tick": int(tick), "agent": int(agent),
                 "path": path.astype("<f8").tobytes()})  # fmt: skip


def agent_header(data: bytes, kind: str, what: str, limit: int) -> tuple[dict, int, int] | Rejected:
    """(message, tick, agent) of a message about one agent (a plan, a record), checked."""
    header = family_header(data, kind, FAMILY_ARENA, what, limit)
    if isinstance(header, Rejected):
        return header
    m, tick = header
    agent = int_field(m, "agent")
    return agent if isinstance(agent, Rejected) else (m, tick, agent)


def parse_plan(data: bytes) -> Plan | Rejected:
    header = agent_header(data, "plan", "a plan", MAX_MESSAGE_BYTES)
    if isinstance(header, Rejected):
        return header
    m, tick, agent = header
    raw = m.get("path")
    if not isinstance(raw, bytes) or len(raw) % 16 or not 0 < len(raw) // 16 <= MAX_PLAN_POINTS:
        return Rejected(f"path: expected 1 to {MAX_PLAN_POINTS} points of 2 float64")
    path = np.frombuffer(raw, dtype="<f8").reshape(-1, 2).astype(np.float64)
    if not np.isfinite(path).all():
        return Rejected("path: not finite")
    return Plan(tick, agent, path)


@dataclass(frozen=True)
class Record:
    tick: int
    agent: int
    values: dict  # key -> a float or a numeric array (swarm.recording.records shows each by its shape)


def record_values(record: dict, tick: int) -> dict:
    """What of a controller's record() travels: numbers every tick, numeric arrays of at most 2
    dimensions every ARRAYS_EVERY ticks; text, None and the like stay home, and so does `path` (the
    plan, sent on plans/<group> when it changes)."""
    out: dict = {}
    for key, value in record.items():
        if key == "path":
            continue
        if isinstance(value, bool | int | float | np.number | np.bool_):
            out[str(key)] = float(value)
        elif tick % ARRAYS_EVERY == 0 and isinstance(value, np.ndarray | list | tuple):
            try:
                a = np.asarray(value, np.float64)
            except (TypeError, ValueError):
                continue
            if a.ndim == 0:
                out[str(key)] = float(a)
            elif a.ndim <= 2 and a.size:
                out[str(key)] = a
    return out


def record_message(tick: int, agent: int, values: dict) -> bytes | None:
    """A record() message (values from `record_values`), or None when it would pass MAX_RECORD_BYTES."""
    blob = memory_codec.encode(values)
    if len(blob) > MAX_RECORD_BYTES - 256:
        return None
    return pack({"type": "record", "family": FAMILY_ARENA, "tick": int(tick), "agent": int(agent), "record": blob})


def parse_record(data: bytes) -> Record | Rejected:
    header = agent_header(data, "record", "a record", MAX_RECORD_BYTES)
    if isinstance(header, Rejected):
        return header
    m, tick, agent = header
    if not isinstance(m.get("record"), bytes):
        return Rejected("record: expected the bytes of a record")
    values = memory_codec.decode(m["record"])
    if isinstance(values, Rejected):
        return values
    if not isinstance(values, dict) or not all(isinstance(k, str) for k in values):
        return Rejected("record: expected a map of names to numbers and arrays")
    for value in values.values():  # the reason names no key: the world counts reasons by their text
        if not (isinstance(value, float) or (isinstance(value, np.ndarray) and value.dtype == np.float64
                and 1 <= value.ndim <= 2)):  # fmt: skip
            return Rejected("record: a value is not a number or a numeric array of 1 or 2 dimensions")
    return Record(tick, agent, values)
