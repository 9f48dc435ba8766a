"""The wire protocol between the world and agent processes (msgpack over zenoh).

Key expressions, all under one prefix per run, `swarm/<run>/`:

    info              queryable: the run's scenario summary and state
    join              queryable: an agent asks to join, the world answers its id
    obs/<id>          world -> agent: perception for one tick
    act/<id>          agent -> world: the action for that tick
    marks/<cell>      agent -> world: a mark write on the agent's cell (merged by min);
                      `get swarm/<run>/marks/**` returns the marking environment
    alive/<id>        liveliness token of an agent
    state             world -> anyone: per-tick summary

`cell` is an opaque integer handed to the agent runtime in each observation
(the controller never sees it).  Every message carries `v` (protocol version)
and agent messages carry `family` ("grid" now; the continuous controllers to
come send wheel commands under another family without changing this layout).
Decoding never raises on bad input: it returns a `Rejected` reason, counted
by the world.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import msgpack
import numpy as np

from agents.controllers.layout import ACT_LEN, PERC_F_LEN, PERC_LEN

VERSION = 1
FAMILY_GRID = "grid"
FAMILIES = (FAMILY_GRID,)
MAX_MESSAGE_BYTES = 64 * 1024
INT64_MAX = 2**63 - 1


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
        self.alive_all = f"{self.prefix}/alive/*"

    def obs(self, agent: int) -> str:
        return f"{self.prefix}/obs/{agent}"

    def act(self, agent: int) -> str:
        return f"{self.prefix}/act/{agent}"

    def mark(self, cell: int) -> str:
        return f"{self.prefix}/marks/{cell}"

    def alive(self, agent: int) -> str:
        return f"{self.prefix}/alive/{agent}"


@dataclass(frozen=True)
class Rejected:
    reason: str


def pack(message: dict) -> bytes:
    return msgpack.packb({"v": VERSION, **message}, use_bin_type=True)


def unpack(data: bytes) -> dict | Rejected:
    if len(data) > MAX_MESSAGE_BYTES:
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


def _int(message: dict, key: str, low: int = 0, high: int = INT64_MAX) -> int | Rejected:
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


def join_request(nonce: str, family: str = FAMILY_GRID, controller: str = "cmarking") -> bytes:
    return pack({"type": "join", "nonce": nonce, "family": family, "controller": controller})


def join_reply(agent: int, nonce: str, info: dict) -> bytes:
    return pack({"type": "welcome", "agent": agent, "nonce": nonce, **info})


def refuse_reply(reason: str) -> bytes:
    return pack({"type": "refused", "reason": reason})


def observation(tick: int, agent: int, cell: int, pi: np.ndarray, pf: np.ndarray) -> bytes:
    return pack({"type": "obs", "tick": tick, "agent": agent, "cell": cell,
                 "pi": pi.tolist(), "pf": pf.tolist()})  # fmt: skip


def action(tick: int, agent: int, act: np.ndarray, marked: bool) -> bytes:
    """`marked`: a mark write for this tick was put on the marks key space (zenoh
    does not order puts on different keys, so the world waits for both)."""
    return pack({"type": "act", "family": FAMILY_GRID, "tick": tick, "agent": agent, "act": act.tolist(),
                 "marked": bool(marked)})  # fmt: skip


def mark_write(tick: int, agent: int, value: int) -> bytes:
    return pack({"type": "mark", "family": FAMILY_GRID, "tick": tick, "agent": agent, "value": value})


def stop_message(reason: str) -> bytes:
    return pack({"type": "stop", "reason": reason})


@dataclass(frozen=True)
class Obs:
    tick: int
    agent: int
    cell: int
    pi: np.ndarray
    pf: np.ndarray


@dataclass(frozen=True)
class Act:
    tick: int
    agent: int
    act: np.ndarray
    marked: bool


@dataclass(frozen=True)
class MarkWrite:
    tick: int
    agent: int
    value: int


def parse_obs(data: bytes) -> Obs | Rejected | dict:
    """An observation, or the raw dict of a `stop` message."""
    m = unpack(data)
    if isinstance(m, Rejected):
        return m
    if m.get("type") == "stop":
        return m
    if m.get("type") != "obs":
        return Rejected("not an observation")
    pi = _ints(m, "pi", PERC_LEN)
    pf = m.get("pf")
    if isinstance(pi, Rejected):
        return pi
    if not isinstance(pf, list) or len(pf) != PERC_F_LEN or not all(isinstance(x, float) for x in pf):
        return Rejected("pf: expected floats")
    fields = [_int(m, k) for k in ("tick", "agent", "cell")]
    for f in fields:
        if isinstance(f, Rejected):
            return f
    return Obs(fields[0], fields[1], fields[2], pi, np.array(pf, dtype=np.float64))


def parse_act(data: bytes) -> Act | Rejected:
    m = unpack(data)
    if isinstance(m, Rejected):
        return m
    if m.get("type") != "act":
        return Rejected("not an action")
    if m.get("family") not in FAMILIES:
        return Rejected("unknown controller family")
    tick, agent = _int(m, "tick"), _int(m, "agent")
    act = _ints(m, "act", ACT_LEN)
    for f in (tick, agent, act):
        if isinstance(f, Rejected):
            return f
    if not isinstance(m.get("marked"), bool):
        return Rejected("marked: expected true or false")
    return Act(tick, agent, act, m["marked"])


def parse_mark(data: bytes) -> MarkWrite | Rejected:
    m = unpack(data)
    if isinstance(m, Rejected):
        return m
    if m.get("type") != "mark" or m.get("family") not in FAMILIES:
        return Rejected("not a mark write")
    tick, agent, value = _int(m, "tick"), _int(m, "agent"), _int(m, "value", 0, 2**62)
    for f in (tick, agent, value):
        if isinstance(f, Rejected):
            return f
    return MarkWrite(tick, agent, value)


def parse_join(data: bytes) -> dict | Rejected:
    m = unpack(data)
    if isinstance(m, Rejected):
        return m
    if m.get("type") != "join" or not isinstance(m.get("nonce"), str) or len(m["nonce"]) > 128:
        return Rejected("not a join request")
    if m.get("family") not in FAMILIES:
        return Rejected("unknown controller family")
    return m


def describe(value: Any) -> str:
    return value.reason if isinstance(value, Rejected) else "ok"
