"""The wire protocol between the world and agent processes (msgpack over zenoh).

Key expressions, all under one prefix per run, `swarm/<run>/`:

    info              queryable: the run's scenario summary and state
    join              queryable: an agent asks to join, the world answers its id
    obs/<group>       world -> agent process: perceptions of its agents for one tick
    act/<group>       agent process -> world: their actions for that tick
    marks/<group>     agent process -> world: their mark writes (merged by min);
                      `get swarm/<run>/marks/**` returns the marking environment
    plans/<group>     agent process -> world (arena): a path a controller planned, for the recording
    alive/<id>        liveliness token of an agent
    state             world -> anyone: per-tick summary

A group is one agent process (`swarm agent --count K` runs K agents): one
message per process and tick each way, arrays as binary blocks.  `cells` are
opaque integers handed to the agent runtime (the controller never sees them).
Every message carries `v` (protocol version) and agent messages carry
`family`: "grid" (this module) or "arena" (swarm/protocol_arena.py: sensor
readings out, wheel speeds back, on the same keys).
Decoding never raises on bad input: it returns a `Rejected` reason, counted
by the world.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import msgpack
import numpy as np

from agents.controllers.layout import ACT_LEN, PERC_F_LEN, PERC_LEN

VERSION = 1
FAMILY_GRID = "grid"
FAMILY_ARENA = "arena"
FAMILIES = (FAMILY_GRID, FAMILY_ARENA)
MAX_MESSAGE_BYTES = 64 * 1024
MAX_WELCOME_BYTES = 16 * 1024 * 1024  # an arena agent's welcome carries its map
INT64_MAX = 2**63 - 1
ENDED = "the run has ended"  # the world's refusal to a join after the run (the agent then exits quietly)


class Keys:
    """Key expressions of one run."""

    def __init__(self, run: str):
        if not run or any(ch in run for ch in "/*$?#"):
            raise ValueError(f"run id {run!r}: use letters, digits, '-' and '_' only")
        self.run = run
        self.prefix = f"swarm/{run}"
        self.info = f"{self.prefix}/info"
        self.join = f"{self.prefix}/join"
        self.state = f"{self.prefix}/state"
        self.acts = f"{self.prefix}/act/*"
        self.marks = f"{self.prefix}/marks/**"
        self.plans = f"{self.prefix}/plans/*"
        self.alive_all = f"{self.prefix}/alive/*"

    def obs(self, group: str) -> str:
        return f"{self.prefix}/obs/{group}"

    def act(self, group: str) -> str:
        return f"{self.prefix}/act/{group}"

    def mark(self, group: str) -> str:
        return f"{self.prefix}/marks/{group}"

    def plan(self, group: str) -> str:
        return f"{self.prefix}/plans/{group}"

    def alive(self, agent: int) -> str:
        return f"{self.prefix}/alive/{agent}"


@dataclass(frozen=True)
class Rejected:
    reason: str


def pack(message: dict) -> bytes:
    return msgpack.packb({"v": VERSION, **message}, use_bin_type=True)


def unpack(data: bytes, limit: int = MAX_MESSAGE_BYTES) -> dict | Rejected:
    if len(data) > limit:
        return Rejected("too large")
    try:
        message = msgpack.unpackb(data, raw=False, strict_map_key=True)
    except Exception:
        return Rejected("not msgpack")
    if not isinstance(message, dict):
        return Rejected("not a map")
    if message.get("v") != VERSION:
        return Rejected("wrong protocol version")
    return message


def int_field(message: dict, key: str, low: int = 0, high: int = INT64_MAX) -> int | Rejected:
    value = message.get(key)
    if isinstance(value, bool) or not isinstance(value, int):
        if isinstance(value, float) and not math.isfinite(value):
            return Rejected(f"{key}: not finite")
        return Rejected(f"{key}: expected an integer")
    if not low <= value <= high:
        return Rejected(f"{key}: out of range")
    return value


def _ints(message: dict, key: str, length: int) -> np.ndarray | Rejected:
    values = message.get(key)
    if not isinstance(values, list) or len(values) != length:
        return Rejected(f"{key}: expected {length} integers")
    if not all(isinstance(v, int) and not isinstance(v, bool) and -INT64_MAX <= v <= INT64_MAX for v in values):
        return Rejected(f"{key}: expected {length} integers")
    return np.array(values, dtype=np.int64)


# ------------------------------------------------------------------- messages


def join_request(nonce: str, group: str, family: str = FAMILY_GRID, controller: str = "cmarking") -> bytes:
    """`group`: the agent process (letters and digits); observations and
    actions of all agents of one process travel together."""
    return pack({"type": "join", "nonce": nonce, "group": group, "family": family, "controller": controller})


def join_reply(agent: int, nonce: str, info: dict) -> bytes:
    return pack({"type": "welcome", "agent": agent, "nonce": nonce, **info})


def refuse_reply(reason: str) -> bytes:
    return pack({"type": "refused", "reason": reason})


def observations(tick: int, agents: np.ndarray, cells: np.ndarray, pi: np.ndarray, pf: np.ndarray) -> bytes:
    """One message for every agent of one agent process: pi (K x PERC_LEN int64)
    and pf (K x PERC_F_LEN float64) travel as little-endian binary blocks."""
    return pack({"type": "obs", "tick": tick, "agents": agents.tolist(), "cells": cells.tolist(),
                 "pi": pi.astype("<i8").tobytes(), "pf": pf.astype("<f8").tobytes()})  # fmt: skip


def actions(tick: int, agents: list[int], acts: np.ndarray, marked: list[bool]) -> bytes:
    """The actions of one agent process for one tick.  `marked[i]`: agent i put a
    mark write for this tick on the marks key space (zenoh does not order puts
    on different keys, so the world waits for both)."""
    return pack({"type": "act", "family": FAMILY_GRID, "tick": tick, "agents": list(agents),
                 "acts": acts.astype("<i8").tobytes(), "marked": [bool(m) for m in marked]})  # fmt: skip


def mark_writes(tick: int, agents: list[int], cells: list[int], values: list[int]) -> bytes:
    """UPDATE-VALUE writes of one agent process for one tick, merged by min."""
    return pack({"type": "mark", "family": FAMILY_GRID, "tick": tick, "agents": list(agents), "cells": list(cells),
                 "values": list(values)})  # fmt: skip


def stop_message(reason: str) -> bytes:
    return pack({"type": "stop", "reason": reason})


@dataclass(frozen=True)
class Obs:
    tick: int
    agents: np.ndarray  # (K,)
    cells: np.ndarray  # (K,)
    pi: np.ndarray  # (K, PERC_LEN)
    pf: np.ndarray  # (K, PERC_F_LEN)


@dataclass(frozen=True)
class Acts:
    tick: int
    agents: np.ndarray  # (K,)
    acts: np.ndarray  # (K, ACT_LEN)
    marked: np.ndarray  # (K,) bool


@dataclass(frozen=True)
class Marks:
    tick: int
    agents: np.ndarray
    cells: np.ndarray
    values: np.ndarray


def int_list(m: dict, key: str, high: int = INT64_MAX) -> np.ndarray | Rejected:
    values = m.get(key)
    if not isinstance(values, list) or len(values) > 100_000:
        return Rejected(f"{key}: expected a list of integers")
    if not all(isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= high for v in values):
        return Rejected(f"{key}: expected integers in range")
    return np.array(values, dtype=np.int64)


def _block(m: dict, key: str, rows: int, cols: int, dtype: str) -> np.ndarray | Rejected:
    raw = m.get(key)
    if not isinstance(raw, bytes) or len(raw) != rows * cols * 8:
        return Rejected(f"{key}: expected {rows}x{cols} binary values")
    block = np.frombuffer(raw, dtype=dtype).reshape(rows, cols)
    if dtype == "<f8" and not np.isfinite(block).all():
        return Rejected(f"{key}: not finite")
    return block.astype(np.int64 if dtype == "<i8" else np.float64)


def first_rejection(*values):
    return next((v for v in values if isinstance(v, Rejected)), None)


def parse_obs(data: bytes) -> Obs | Rejected | dict:
    """A batch of observations, or the raw dict of a `stop` message."""
    m = unpack(data)
    if isinstance(m, Rejected):
        return m
    if m.get("type") == "stop":
        return m
    if m.get("type") != "obs":
        return Rejected("not an observation")
    tick, agents, cells = int_field(m, "tick"), int_list(m, "agents"), int_list(m, "cells")
    if bad := first_rejection(tick, agents, cells):
        return bad
    if len(cells) != len(agents):
        return Rejected("cells: one per agent")
    pi, pf = _block(m, "pi", len(agents), PERC_LEN, "<i8"), _block(m, "pf", len(agents), PERC_F_LEN, "<f8")
    if bad := first_rejection(pi, pf):
        return bad
    return Obs(tick, agents, cells, pi, pf)


def family_message(data: bytes, kind: str, family: str, what: str, limit: int = MAX_MESSAGE_BYTES) -> dict | Rejected:
    """A message of this type and controller family, unpacked."""
    m = unpack(data, limit)
    return m if isinstance(m, Rejected) else check_family(m, kind, family, what)


def check_family(m: dict, kind: str, family: str, what: str) -> dict | Rejected:
    if m.get("type") != kind:
        return Rejected(f"not {what}")
    if m.get("family") != family:
        return Rejected("unknown controller family")
    return m


def act_header(data: bytes, family: str) -> tuple[dict, int, np.ndarray] | Rejected:
    """What every family's action message shares: (message, tick, agents)."""
    m = family_message(data, "act", family, "an action")
    if isinstance(m, Rejected):
        return m
    tick, agents = int_field(m, "tick"), int_list(m, "agents")
    if bad := first_rejection(tick, agents):
        return bad
    return m, tick, agents  # type: ignore[return-value]


def parse_acts(data: bytes) -> Acts | Rejected:
    header = act_header(data, FAMILY_GRID)
    if isinstance(header, Rejected):
        return header
    m, tick, agents = header
    acts = _block(m, "acts", len(agents), ACT_LEN, "<i8")
    if isinstance(acts, Rejected):
        return acts
    marked = m.get("marked")
    if not isinstance(marked, list) or len(marked) != len(agents) or not all(isinstance(x, bool) for x in marked):
        return Rejected("marked: expected one true or false per agent")
    return Acts(tick, agents, acts, np.array(marked, dtype=bool))


def parse_marks(data: bytes) -> Marks | Rejected:
    m = unpack(data)
    if isinstance(m, Rejected):
        return m
    if m.get("type") != "mark" or m.get("family") not in FAMILIES:
        return Rejected("not a mark write")
    tick = int_field(m, "tick")
    agents, cells, values = int_list(m, "agents"), int_list(m, "cells"), int_list(m, "values", 2**62)
    if bad := first_rejection(tick, agents, cells, values):
        return bad
    if not len(agents) == len(cells) == len(values):
        return Rejected("agents, cells, values: one each per write")
    return Marks(tick, agents, cells, values)


def parse_join(data: bytes) -> dict | Rejected:
    m = unpack(data)
    if isinstance(m, Rejected):
        return m
    if m.get("type") != "join" or not isinstance(m.get("nonce"), str) or len(m["nonce"]) > 128:
        return Rejected("not a join request")
    group = m.get("group")
    if not isinstance(group, str) or not 0 < len(group) <= 64 or not group.isalnum():
        return Rejected("group: expected 1 to 64 letters and digits")
    if m.get("family") not in FAMILIES:
        return Rejected("unknown controller family")
    return m
