"""Every message decoder, fuzzed: random bytes and the project's own messages mutated (keys dropped and
added, wrong types, NaN and inf, boundary integers, odd dtypes and shapes, cut or flipped bytes, headers
that claim huge lengths).  Each input gives the decoded message or a `Rejected` reason that the decoders
name, within the time and memory its size allows: never an exception (tests/fuzz.py; a long run:
docs/testing.md)."""

from __future__ import annotations

import msgpack
import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from swarm.core import memory_codec, wire
from tests.fuzz import FUZZ, TALLY, decode, inputs, reason_patterns, tally_table, values
from world_server.arena.face import wire as arena
from world_server.grid.face import wire as grid
from world_server.grid.face.layout import ACT_LEN, MEM_LEN, PERC_F_LEN

REASONS = reason_patterns("swarm/core/wire.py", "swarm/core/memory_codec.py", "world_server/grid/face/wire.py",
                          "world_server/arena/face/wire.py")  # fmt: skip
NONCE = "0123456789abcdef"


@pytest.fixture(scope="module", autouse=True)
def _report_tally():
    """The rejections by reason, printed after the module (seen with `-s`); every decoder rejected something."""
    yield
    print(f"\ninputs decoded and rejections by decoder and reason ({sum(TALLY.values())} rejections):\n{tally_table()}")


def _rng(seed: int) -> np.random.Generator:
    return np.random.default_rng(seed)


seeds = st.integers(0, 2**32 - 1)
counts = st.integers(0, 4)
ticks = st.sampled_from([0, 1, 127, 128, 65_536, 2**33, wire.INT64_MAX])

# ------------------------------------------------------------ the envelope


@FUZZ
@given(inputs(st.builds(wire.join_request, st.text(max_size=20), st.text("abc123", min_size=1, max_size=8),
                 st.sampled_from(wire.FAMILIES), st.text(max_size=10))))  # fmt: skip
@example(wire.pack({"type": "join", "nonce": "n", "group": "g", "family": ["grid"]}))  # a list: unhashable
def test_join_requests(data):
    decode("join", wire.parse_join, data, dict, REASONS)


def _welcome(seed: int, agent: int, arena_family: bool) -> bytes:
    rng = _rng(seed)
    if arena_family:
        memory = memory_codec.encode({"t": int(rng.integers(99)), "f": rng.random(3)})
        params = {"map": {"size": [3.0, 2.0]}, "goal": [1.0, 1.0]}
        info = {"family": "arena", "controller": "carrot", "params": params, "recorded": False, "memory": memory}
    else:
        info = {"controller": "cmarking", "params": rng.random(4).tolist(), "memory": [0] * MEM_LEN}
    return wire.join_reply(agent, NONCE, {"run": "r", "seed": seed, "tick": 3, "lockstep": True, **info})


welcomes = st.builds(_welcome, seeds, st.integers(0, 500), st.booleans()) | st.builds(wire.refuse_reply, st.text())


@FUZZ
@given(inputs(welcomes))
@example(wire.join_reply(1, NONCE, {"seed": 2}))  # no params
@example(wire.pack({"type": "welcome", "nonce": NONCE, "agent": "1", "seed": 2, "params": []}))
@example(wire.pack({"type": "refused", "reason": None}))
def test_welcomes(data):
    decode("welcome", wire.parse_welcome, data, dict, REASONS, NONCE)


# ------------------------------------------------------------ the grid family


def _grid_obs(seed: int, k: int, tick: int) -> bytes:
    rng = _rng(seed)
    return grid.observations(tick, rng.integers(-5, 99, (k, grid.OBS_INTS)), rng.random((k, PERC_F_LEN)))


def _grid_acts(seed: int, k: int, tick: int) -> bytes:
    rng = _rng(seed)
    return grid.actions(tick, np.arange(k), rng.integers(0, 5, (k, ACT_LEN)), rng.integers(0, 2, k),
                        rng.integers(0, 9, (k, MEM_LEN)))  # fmt: skip


grid_to_agent = (st.builds(_grid_obs, seeds, counts, ticks) | st.builds(wire.stop_message, st.text(max_size=8))
                 | st.builds(lambda s, k: grid.memory_message(np.arange(k), _rng(s).integers(0, 9, (k, MEM_LEN))),
                             seeds, counts))  # fmt: skip


@FUZZ
@given(inputs(grid_to_agent))
@example(wire.pack({"type": "memory", "rows": b"\x00" * 8 * (1 + MEM_LEN) * 100_001}))  # too many rows
def test_grid_observations(data):
    decode("grid obs", grid.parse_obs, data, (grid.Obs, grid.Memory, dict), REASONS)


@FUZZ
@given(inputs(st.builds(_grid_acts, seeds, st.integers(1, 4), ticks)))
def test_grid_actions(data):
    decode("grid act", grid.parse_acts, data, grid.Acts, REASONS)


# ----------------------------------------------------------- the arena family


def _perception(rng: np.random.Generator) -> dict:
    return {"ir": rng.random(8), "laser": rng.random((2, 3)), "camera": rng.integers(0, 255, (2, 2, 3), np.uint8),
            "bumped": rng.random(2) < 0.5, "count": rng.integers(0, 9, 1),
            "pose": np.float64(rng.random())}  # fmt: skip


def _shared(rng: np.random.Generator, k: int) -> list:
    return [(a, "map", msgpack.packb({"n": int(rng.integers(9))})) for a in range(k) if rng.random() < 0.5]


def _arena_obs(seed: int, k: int, tick: int, keep: bool) -> bytes:
    rng = _rng(seed)
    return arena.observations(tick, range(k), [_perception(rng) for _ in range(k)], _shared(rng, k), keep)


def _memory(rng: np.random.Generator) -> dict:
    """A controller's memory as the arena's controllers keep it: numbers, text, maps with int keys, arrays."""
    return {"tick": int(rng.integers(1 << 40)), "phase": "explore", "visits": {3: 1, 7: 2}, "pose": rng.random(3),
            "field": rng.random((3, 4)).astype(np.float32), "cells": rng.integers(0, 9, (2, 2)),
            "seen": rng.random(5) < 0.5, "none": None, "path": [(1.0, 2.0), (3.0, 4.0)]}  # fmt: skip


def _blobs(seed: int, k: int) -> list:
    rng = _rng(seed)
    return [(a, memory_codec.encode(_memory(rng))) for a in range(k)]


def _arena_acts(seed: int, k: int, tick: int) -> bytes:
    rng = _rng(seed)
    wheels = np.column_stack([rng.normal(0, 0.2, (k, 2)), rng.integers(0, 2, k)])
    memory = _blobs(seed, k) if rng.random() < 0.5 else []
    rab = [(a, rng.bytes(4)) for a in range(k) if rng.random() < 0.5]
    return arena.actions(tick, range(k), wheels, _shared(rng, k), memory, rab)


arena_to_agent = (st.builds(_arena_obs, seeds, counts, ticks, st.booleans())
                  | st.builds(lambda s, k: arena.memory_message(_blobs(s, k)), seeds, st.integers(1, 3))
                  | st.builds(wire.stop_message, st.text(max_size=8)))  # fmt: skip
ARENA_OBS = (arena.ArenaObs, arena.ArenaMemory, dict)


@FUZZ
@given(inputs(arena_to_agent))
@example(wire.pack({"type": "obs", "family": "arena", "tick": 1, "agents": [0],  # a dtype that cannot be a key
                    "perceptions": [{"ir": [["<f8"], [1], b"\x00" * 8]}]}))  # fmt: skip
@example(wire.pack({"type": "obs", "family": "arena", "tick": 1, "agents": [0],  # a shape of 2^80 elements
                    "perceptions": [{"ir": ["<f8", [1 << 20] * 4, b""]}]}))  # fmt: skip
def test_arena_observations(data):
    decode("arena obs", arena.parse_obs, data, ARENA_OBS, REASONS)


@FUZZ
@given(inputs(st.builds(_arena_acts, seeds, st.integers(1, 4), ticks)))
def test_arena_actions(data):
    decode("arena act", arena.parse_acts, data, arena.ArenaActs, REASONS)


def _path(seed: int, points: int) -> np.ndarray:
    return _rng(seed).normal(0, 3, (points, 2))


@FUZZ
@given(inputs(st.builds(lambda s, t, a, p: arena.plan_message(t, a, _path(s, p)), seeds, ticks, st.integers(0, 99),
                 st.integers(1, 2500))))  # fmt: skip
def test_arena_plans(data):
    decode("arena plan", arena.parse_plan, data, arena.Plan, REASONS)


def _record(seed: int, tick: int) -> bytes:
    rng = _rng(seed)
    values_ = arena.record_values({"speed": rng.random(), "n": int(rng.integers(9)), "field": rng.random((3, 3)),
                                   "trace": list(rng.random(4)), "name": "x"}, tick)  # fmt: skip
    return arena.record_message(tick, int(rng.integers(99)), values_)


@FUZZ
@given(inputs(st.builds(_record, seeds, st.sampled_from([0, 10, 11]))))
@example(wire.pack({"type": "record", "family": "arena", "tick": 1, "agent": 0,  # a key of 1 MB in the reason
                    "record": memory_codec.encode({"k" * 500_000: "text"})}))  # fmt: skip
def test_arena_records(data):
    decode("arena record", arena.parse_record, data, arena.Record, REASONS)


# The field parsers take what msgpack decoded: any value at all.
@FUZZ
@given(values() | st.lists(st.lists(values(), max_size=4), max_size=4), st.lists(st.integers(-2, 5), max_size=4))
def test_arena_field_parsers(raw, agents):
    named = np.array(agents, np.int64)
    decode("arena memory field", arena.parse_memory, raw, list, REASONS, named)
    decode("arena shared field", arena.parse_shared, raw, list, REASONS)
    decode("arena rab field", arena.parse_rab, raw, list, REASONS, named)


# ------------------------------------------------------------ memory blobs


@FUZZ
@given(inputs(st.builds(lambda s: memory_codec.encode(_memory(_rng(s))), seeds)), st.booleans())
@example(memory_codec.encode(np.zeros((0, 0))).replace(b"<f8", b"|V0"), False)  # a dtype of no bytes
@example(msgpack.packb(msgpack.ExtType(1, msgpack.packb(["<f8", [1 << 62, 1 << 62], b""]))), True)
def test_memory_blobs(blob, views):
    result = decode("memory", memory_codec.decode, blob, object, REASONS, views)
    if isinstance(result, np.ndarray):
        assert result.nbytes <= len(blob)  # an array is never larger than the bytes that held it


def test_a_valid_message_of_every_kind_decodes():
    """The mutations start from messages the decoders accept (else the fuzzing would only test rejections)."""
    rng = _rng(1)
    assert isinstance(wire.parse_join(wire.join_request(NONCE, "g1", "arena")), dict)
    assert wire.parse_welcome(_welcome(3, 4, True), NONCE)["agent"] == 4
    assert wire.parse_welcome(_welcome(3, 4, False), NONCE)["seed"] == 3
    assert isinstance(grid.parse_obs(_grid_obs(1, 3, 9)), grid.Obs)
    assert isinstance(grid.parse_acts(_grid_acts(1, 3, 9)), grid.Acts)
    assert isinstance(arena.parse_obs(_arena_obs(1, 3, 9, True)), arena.ArenaObs)
    assert isinstance(arena.parse_obs(arena.memory_message(_blobs(1, 2))), arena.ArenaMemory)
    acts = arena.parse_acts(_arena_acts(2, 3, 9))
    assert isinstance(acts, arena.ArenaActs) and acts.wheels.shape == (3, 3)
    assert isinstance(arena.parse_plan(arena.plan_message(1, 2, _path(1, 5))), arena.Plan)
    assert isinstance(arena.parse_record(_record(1, 10)), arena.Record)
    memory = memory_codec.decode(memory_codec.encode(_memory(rng)))
    assert memory["visits"] == {3: 1, 7: 2} and memory["field"].dtype == np.float32


def test_the_reasons_are_those_the_decoders_name():
    """The check's patterns come from the source: a new reason is known without editing the test."""
    assert len(REASONS) > 40
    assert any(p.fullmatch("wheels: expected 2 binary float64 per agent") for p in REASONS)
    assert not any(p.fullmatch("KeyError: 'agent'") for p in REASONS)
