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
import struct
from dataclasses import dataclass
from typing import NamedTuple

import msgpack
import numpy as np

from agents.controllers.layout import ACT_LEN, MEM_LEN, PERC_F_LEN, PERC_LEN, new_memory
from swarm import msgpack_views

VERSION = 2
FAMILY_GRID = "grid"
FAMILY_ARENA = "arena"
FAMILIES = (FAMILY_GRID, FAMILY_ARENA)
MAX_MESSAGE_BYTES = 64 * 1024
NOT_PLAIN = -2  # agents.controllers.envelope: not a plain observation, the Python parser takes it
ENVELOPE = 64  # bytes of a grid action message besides its rows
MAX_WELCOME_BYTES = 16 * 1024 * 1024  # an arena agent's welcome carries its map
INT64_MAX = 2**63 - 1
OBS_PERCEPTION = 2  # an observation row: agent, cell, then the integer perception
OBS_INTS = OBS_PERCEPTION + PERC_LEN
R_AGENT, R_ACT = 0, 1  # an action row: agent, action (ACT_LEN), marked, memory (MEM_LEN)
R_MARKED = R_ACT + ACT_LEN
R_MEM = R_MARKED + 1
ACT_ROW = R_MEM + MEM_LEN
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
    (swarm/msgpack_views.py): for a message that carries MBs, such as memories handed back."""
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


def observations(tick: int, ints: np.ndarray, pf: np.ndarray) -> bytes:
    """One message for every agent of one agent process.  `ints` (K x OBS_INTS,
    int64) holds per row the agent, its cell and its integer perception; `pf`
    (K x PERC_F_LEN, float64) its float perception; both little-endian blocks."""
    return pack({"type": "obs", "tick": tick, "ints": ints.astype("<i8", copy=False).tobytes(),
                 "pf": pf.astype("<f8", copy=False).tobytes()})  # fmt: skip


def pack_actions(tick: int, rows: np.ndarray) -> bytes:
    """The actions of one agent process for one tick: `rows` (K x ACT_ROW, int64)
    hold per agent its id, action (its mark write included: the world checks
    it against UPDATE-VALUE on the agent's cell and applies it with the tick),
    whether that write lowers the mark it perceived, and its controller memory
    after the step (the world keeps it, so a restarted world resumes every
    controller exactly)."""
    return pack({"type": "act", "family": FAMILY_GRID, "tick": tick, "rows": rows.astype("<i8", copy=False).tobytes()})


def action_rows(agents, acts: np.ndarray, marked, memory: np.ndarray | None = None) -> np.ndarray:
    """Rows for `pack_actions` from separate columns (tests and tools)."""
    rows = np.zeros((len(agents), ACT_ROW), dtype=np.int64)
    rows[:, R_AGENT] = agents
    rows[:, R_ACT : R_ACT + ACT_LEN] = np.asarray(acts).reshape(len(agents), -1)[:, :ACT_LEN]
    rows[:, R_MARKED] = np.asarray(marked, dtype=np.int64)
    rows[:, R_MEM:] = new_memory(len(agents)) if memory is None else memory
    return rows


def actions(tick: int, agents, acts: np.ndarray, marked, memory: np.ndarray | None = None) -> bytes:
    return pack_actions(tick, action_rows(agents, acts, marked, memory))


def memory_message(agents: np.ndarray, memory: np.ndarray) -> bytes:
    """World -> agent process, before the first tick of a resumed run: the
    controller memory each of its agents had at the saved tick."""
    rows = np.column_stack([np.asarray(agents, dtype=np.int64), memory]).astype("<i8")
    return pack({"type": "memory", "rows": rows.tobytes()})


def stop_message(reason: str) -> bytes:
    return pack({"type": "stop", "reason": reason})


@dataclass(frozen=True)
class Obs:
    tick: int
    ints: np.ndarray  # (K, OBS_INTS): agent, cell, integer perception
    pf: np.ndarray  # (K, PERC_F_LEN)

    @property
    def agents(self) -> np.ndarray:
        return self.ints[:, 0]

    @property
    def cells(self) -> np.ndarray:
        return self.ints[:, 1]

    @property
    def pi(self) -> np.ndarray:
        return self.ints[:, 2:]


class ObsBlocks(NamedTuple):
    tick: int
    ints: bytes  # K x OBS_INTS little-endian int64, unchecked
    pf: bytes  # K x PERC_F_LEN little-endian float64, unchecked


class HandBack:
    """A resumed world's message that gives controllers back their memory (each family its own)."""


@dataclass(frozen=True)
class Memory(HandBack):
    rows: np.ndarray  # (K, 1 + MEM_LEN): agent, memory


@dataclass(frozen=True)
class Acts:
    tick: int
    rows: np.ndarray  # (K, ACT_ROW): agent, action, marked, memory (validated by the world, row by row)


def int_list(m: dict, key: str, high: int = INT64_MAX) -> np.ndarray | Rejected:
    values = m.get(key)
    if not isinstance(values, list) or len(values) > 100_000:
        return Rejected(f"{key}: expected a list of integers")
    if not all(isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= high for v in values):
        return Rejected(f"{key}: expected integers in range")
    return np.array(values, dtype=np.int64)


def first_rejection(*values):
    return next((v for v in values if isinstance(v, Rejected)), None)


def _rows(raw, key: str, cols: int, dtype: str, limit: int = 100_000) -> np.ndarray | Rejected:
    """A binary block of whole rows, copied (writable, native)."""
    width = cols * 8
    if not isinstance(raw, bytes) or len(raw) % width or len(raw) // width > limit:
        return Rejected(f"{key}: expected rows of {cols} binary values")
    return np.frombuffer(raw, dtype=dtype).reshape(-1, cols).copy()


def obs_blocks(data: bytes) -> ObsBlocks | Memory | Rejected | dict:
    """The agent's hot path: the header checked, the blocks left as bytes (the
    compiled step checks their shapes and values, `dispatch.answer_rows`).
    Also a resumed run's controller memory, or the raw dict of a `stop` (or
    `wake`) message."""
    m = unpack(data)
    if isinstance(m, Rejected):
        return m
    kind = m.get("type")
    if kind in ("stop", "wake"):
        return m
    if kind == "memory":
        rows = _rows(m.get("rows"), "rows", 1 + MEM_LEN, "<i8")
        return rows if isinstance(rows, Rejected) else Memory(rows)
    if kind != "obs":
        return Rejected("not an observation")
    tick, ints, pf = m.get("tick"), m.get("ints"), m.get("pf")
    if type(tick) is not int or not 0 <= tick <= INT64_MAX:
        return Rejected("tick: expected an integer")
    if type(ints) is not bytes or type(pf) is not bytes:
        return Rejected("ints, pf: expected binary blocks")
    return ObsBlocks(tick, ints, pf)


def parse_obs(data: bytes) -> Obs | Memory | Rejected | dict:
    """`obs_blocks` with the blocks checked and decoded (tools and tests)."""
    blocks = obs_blocks(data)
    if not isinstance(blocks, ObsBlocks):
        return blocks
    ints, pf = _rows(blocks.ints, "ints", OBS_INTS, "<i8"), _rows(blocks.pf, "pf", PERC_F_LEN, "<f8")
    if bad := first_rejection(ints, pf):
        return bad
    if len(pf) != len(ints):
        return Rejected("pf: one row per agent")
    if not np.isfinite(pf).all():
        return Rejected("pf: not finite")
    return Obs(blocks.tick, ints, pf)


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


def parse_acts(data: bytes) -> Acts | Rejected:
    header = family_header(data, "act", FAMILY_GRID, "an action")
    if isinstance(header, Rejected):
        return header
    m, tick = header
    raw = m.get("rows")
    if not isinstance(raw, bytes) or len(raw) % (ACT_ROW * 8):
        return Rejected(f"rows: expected rows of {ACT_ROW} binary integers")
    return Acts(tick, np.frombuffer(raw, dtype="<i8").reshape(-1, ACT_ROW))


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
