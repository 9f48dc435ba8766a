"""The wire every world kind and its agents share: msgpack messages over zenoh.

Key expressions, all under one prefix per run, `swarm/<run>/`:

    info              queryable: the run's scenario summary and state
    join              queryable: an agent asks to join, the world answers its id
    obs/<group>       world -> agent process: perceptions of its agents for one tick
    act/<group>       agent process -> world: their actions for that tick
    marks/<group>     agent process -> world: their mark writes (merged by min);
                      `get swarm/<run>/marks/**` returns the marking environment
    plans/<group>     agent process -> world (arena): a path a controller planned, for the recording
    records/<group>   agent process -> world (arena): a controller's record(), for the recording
    alive/<id>        liveliness token of an agent
    state             world -> anyone: per-tick summary

A group is one agent process (`swarm agent --count K` runs K agents): one
message per process and tick each way, arrays as binary blocks.  Every message
carries `v` (protocol version) and agent messages carry `family`, the world
kind whose face they speak: "grid" (world_server/grid/face/wire.py) or "arena"
(world_server/arena/face/wire.py: sensor readings out, wheel speeds back, on
the same keys).  This module holds what they share: the keys, the envelope,
the join handshake and the checks.  Decoding never raises on bad input: it
returns a `Rejected` reason, counted by the world.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass

import msgpack
import numpy as np

from swarm.core import msgpack_views

VERSION = 2
FAMILY_GRID = "grid"
FAMILY_ARENA = "arena"
FAMILIES = (FAMILY_GRID, FAMILY_ARENA)
MAX_MESSAGE_BYTES = 64 * 1024
MAX_WELCOME_BYTES = 16 * 1024 * 1024  # an arena agent's welcome carries its map
INT64_MAX = 2**63 - 1
ENDED = "the run has ended"  # the world's refusal to a join after the run (the agent then exits quietly)


class Keys:
    """Key expressions of one run."""

    def __init__(self, run: str, every_run: bool = False):
        """`every_run`: `run` is a wildcard (`*`), for rules that hold in any run (the router's access control)."""
        if not every_run and (not run or any(ch in run for ch in "/*$?#")):
            raise ValueError(f"run id {run!r}: use letters, digits, '-' and '_' only")
        self.run = run
        self.prefix = f"swarm/{run}"
        self.info = f"{self.prefix}/info"
        self.join = f"{self.prefix}/join"
        self.state = f"{self.prefix}/state"
        self.acts = f"{self.prefix}/act/*"
        self.marks = f"{self.prefix}/marks/**"
        self.plans = f"{self.prefix}/plans/*"
        self.records = f"{self.prefix}/records/*"
        self.alive_all = f"{self.prefix}/alive/*"

    def obs(self, group: str) -> str:
        return f"{self.prefix}/obs/{group}"

    def act(self, group: str) -> str:
        return f"{self.prefix}/act/{group}"

    def mark(self, group: str) -> str:
        return f"{self.prefix}/marks/{group}"

    def plan(self, group: str) -> str:
        return f"{self.prefix}/plans/{group}"

    def record(self, group: str) -> str:
        return f"{self.prefix}/records/{group}"

    def alive(self, agent: int) -> str:
        return f"{self.prefix}/alive/{agent}"


@dataclass(frozen=True)
class Rejected:
    reason: str


TICK_KEY = b"\xa4tick"  # msgpack's "tick": every agent message has it among its first fields (v, type, family)
UINT_WIDTHS = {0xCC: 1, 0xCD: 2, 0xCE: 4, 0xCF: 8}  # msgpack's uint 8, 16, 32, 64


def peek_tick(data: bytes) -> int | None:
    """The tick an agent message says it is for, read from its first bytes without decoding it (the
    world sorts a flood by it before deciding what to decode), or None.  Only a hint: the message is
    checked whole when it is decoded."""
    at = data.find(TICK_KEY, 0, 64)
    if at < 0 or (at := at + len(TICK_KEY)) >= len(data):
        return None
    if (tag := data[at]) < 0x80:
        return tag
    width = UINT_WIDTHS.get(tag, 0)
    if not width or at + 1 + width > len(data):
        return None
    return int.from_bytes(data[at + 1 : at + 1 + width], "big")


def pack(message: dict) -> bytes:
    return msgpack.packb({"v": VERSION, **message}, use_bin_type=True)


HEADERS = msgpack.Packer(use_bin_type=True)  # array and map headers: `HEADERS.pack_array_header(n)`


def bin_header(size: int) -> bytes:
    """msgpack's header of a `size`-byte bin (msgpack-python's Packer has none to call)."""
    if size < 1 << 8:
        return struct.pack(">BB", 0xC4, size)
    return struct.pack(">BH", 0xC5, size) if size < 1 << 16 else struct.pack(">BI", 0xC6, size)


def pack_ending_with(message: dict, key: str, tail: list) -> bytes:
    """`pack({**message, key: value})`, where `value` is given in its msgpack form as pieces
    (bytes, memoryviews): the message is written once, by one join, with no copy of the pieces
    before it (a DFT robot's memory is MBs of fields)."""
    whole = {"v": VERSION, **message}
    head = [HEADERS.pack_map_header(len(whole) + 1)]
    head += [msgpack.packb(k, use_bin_type=True) + msgpack.packb(v, use_bin_type=True) for k, v in whole.items()]
    return b"".join([*head, msgpack.packb(key), *tail])


def unpack(data: bytes, limit: int = MAX_MESSAGE_BYTES, views: bool = False) -> dict | Rejected:
    """A message's map, or why not.  With `views` its bins are views of `data`, not copies
    (swarm/core/msgpack_views.py): for a message that carries MBs, such as memories handed back."""
    if len(data) > limit:
        return Rejected("too large")
    try:
        message = msgpack_views.unpack(data) if views else msgpack.unpackb(data, raw=False, strict_map_key=True)
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


# ------------------------------------------------------------------- messages


def join_request(nonce: str, group: str, family: str = FAMILY_GRID, controller: str = "cmarking") -> bytes:
    """`group`: the agent process (letters and digits); observations and
    actions of all agents of one process travel together."""
    return pack({"type": "join", "nonce": nonce, "group": group, "family": family, "controller": controller})


def join_reply(agent: int, nonce: str, info: dict) -> bytes:
    return pack({"type": "welcome", "agent": agent, "nonce": nonce, **info})


def refuse_reply(reason: str) -> bytes:
    return pack({"type": "refused", "reason": reason})


def stop_message(reason: str) -> bytes:
    return pack({"type": "stop", "reason": reason})


class HandBack:
    """A resumed world's message that gives controllers back their memory (each family its own)."""


def int_list(m: dict, key: str, high: int = INT64_MAX) -> np.ndarray | Rejected:
    values = m.get(key)
    if not isinstance(values, list) or len(values) > 100_000:
        return Rejected(f"{key}: expected a list of integers")
    if not all(isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= high for v in values):
        return Rejected(f"{key}: expected integers in range")
    return np.array(values, dtype=np.int64)


def first_rejection(*values):
    return next((v for v in values if isinstance(v, Rejected)), None)


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


def family_header(data: bytes, kind: str, family: str, what: str,
                  limit: int = MAX_MESSAGE_BYTES) -> tuple[dict, int] | Rejected:  # fmt: skip
    """What every family's agent message shares: (message, tick), type, family and tick checked."""
    m = family_message(data, kind, family, what, limit)
    if isinstance(m, Rejected):
        return m
    tick = int_field(m, "tick")
    return tick if isinstance(tick, Rejected) else (m, tick)


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


def parse_welcome(data: bytes, nonce: str) -> dict | Rejected:
    """The world's answer to the join `nonce`: a welcome (its agent id, seed and params checked; the rest
    is the family's) or a refusal (with its reason).  Anything else, or a welcome for another join, is
    a reason, and the agent asks again."""
    m = unpack(data, MAX_WELCOME_BYTES)
    if isinstance(m, Rejected):
        return m
    if m.get("type") == "refused":
        return m if isinstance(m.get("reason"), str) else Rejected("refused: expected a reason")
    if m.get("type") != "welcome" or m.get("nonce") != nonce:
        return Rejected("not a welcome for this join")
    if bad := first_rejection(int_field(m, "agent"), int_field(m, "seed", -INT64_MAX - 1)):
        return bad
    if not isinstance(m.get("params"), list | dict):
        return Rejected("params: expected a list or a map")
    return m


def world_info(session, keys: Keys, timeout: float = 2.0) -> dict | None:
    """The world's answer on swarm/<run>/info, or None if no world answers."""
    for reply in session.get(keys.info, timeout=timeout):
        if reply.ok:
            info = unpack(reply.ok.payload.to_bytes())
            if isinstance(info, dict) and info.get("type") == "info":
                return info
    return None
