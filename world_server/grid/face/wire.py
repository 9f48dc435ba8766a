"""The grid family's messages: integer perceptions out, action rows back.

Every grid controller's step reads and writes flat int64/float64 rows
(world_server/grid/face/layout.py), so one message per agent process and
tick carries all its agents' rows as binary blocks.  `cells` are opaque
integers handed to the agent runtime (the controller never sees them).  The
envelope, the keys and the join are swarm.core.wire's.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from swarm.core.wire import (
    FAMILY_GRID,
    INT64_MAX,
    HandBack,
    Rejected,
    family_header,
    first_rejection,
    pack,
    unpack,  # fmt: skip
)
from world_server.grid.face.layout import ACT_LEN, MEM_LEN, PERC_F_LEN, PERC_LEN, new_memory

NOT_PLAIN = -2  # agents.controllers.grid.envelope: not a plain observation, the Python parser takes it
ENVELOPE = 64  # bytes of a grid action message besides its rows
OBS_PERCEPTION = 2  # an observation row: agent, cell, then the integer perception
OBS_INTS = OBS_PERCEPTION + PERC_LEN
R_AGENT, R_ACT = 0, 1  # an action row: agent, action (ACT_LEN), marked, memory (MEM_LEN)
R_MARKED = R_ACT + ACT_LEN
R_MEM = R_MARKED + 1
ACT_ROW = R_MEM + MEM_LEN


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


@dataclass(frozen=True)
class Memory(HandBack):
    rows: np.ndarray  # (K, 1 + MEM_LEN): agent, memory


@dataclass(frozen=True)
class Acts:
    tick: int
    rows: np.ndarray  # (K, ACT_ROW): agent, action, marked, memory (validated by the world, row by row)


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


def parse_acts(data: bytes) -> Acts | Rejected:
    header = family_header(data, "act", FAMILY_GRID, "an action")
    if isinstance(header, Rejected):
        return header
    m, tick = header
    raw = m.get("rows")
    if not isinstance(raw, bytes) or len(raw) % (ACT_ROW * 8):
        return Rejected(f"rows: expected rows of {ACT_ROW} binary integers")
    return Acts(tick, np.frombuffer(raw, dtype="<i8").reshape(-1, ACT_ROW))
