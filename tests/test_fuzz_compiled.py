"""The grid's compiled readers, fuzzed against the Python parser: the world's `accept_message` (actions)
and the agent's `answer_message` (observations) read msgpack bytes in compiled code, where a read past
the end is not an exception but garbage or a crash.  For every mutated message each one either leaves
it to the parser, changing nothing, or does exactly what the parser's result gives (tests/fuzz.py)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from agents.controllers.grid.dispatch import answer_rows
from agents.controllers.grid.envelope import answer_message
from swarm.core import wire
from swarm.scenario import load_scenario
from tests.fuzz import FUZZ, guarded, inputs
from world_server.grid.accept import REFUSALS, accept_message, accept_rows
from world_server.grid.face import wire as grid
from world_server.grid.face.layout import ACT_LEN, MEM_LEN, PERC_F_LEN, controller_kind, controller_params, new_memory

AGENTS = 4
ACTIVE = 2
ticks = st.sampled_from([0, 1, 127, 128, 65_536, 2**33, wire.INT64_MAX])
SCENARIO = load_scenario("setup2")
KIND, PARAMS = controller_kind(SCENARIO.controller), controller_params(SCENARIO)


@pytest.fixture(scope="module", autouse=True)
def _compiled():
    """Both readers compiled (or loaded from numba's cache) before the clock of any input starts."""
    assert _accept(_acts(1, 2, 3), _world()) >= 0
    assert _answer(_obs(1, 2, 3))[0] >= 0


def _world() -> dict:
    return {"acted": np.zeros(AGENTS, bool), "acts": np.zeros((AGENTS, ACT_LEN), np.int64),
            "mark_floor": np.zeros(AGENTS, np.int64), "memory": np.zeros((AGENTS, MEM_LEN), np.int64),
            "refused": np.zeros(len(REFUSALS), np.int64)}  # fmt: skip


def _acts(seed: int, k: int, tick: int) -> bytes:
    rng = np.random.default_rng(seed)
    return grid.actions(tick, rng.integers(-1, AGENTS + 1, k), rng.integers(0, 5, (k, ACT_LEN)),
                        rng.integers(0, 2, k), rng.integers(0, 9, (k, MEM_LEN)))  # fmt: skip


SLOTS, GROUPS = np.full(AGENTS, ACTIVE, np.int64), np.zeros(AGENTS, np.int64)


def _accept(data: bytes, w: dict) -> int:
    """The world's reader on `data` from process 0, any tick in the window, into the world `w`."""
    return accept_message(np.frombuffer(data, np.uint8), 0, wire.INT64_MAX, SLOTS, GROUPS, 0, True, w["acted"],
                          w["acts"], w["mark_floor"], w["memory"], w["refused"])  # fmt: skip


@FUZZ
@given(inputs(st.builds(_acts, st.integers(0, 2**32 - 1), st.integers(1, AGENTS), ticks)))
def test_the_worlds_compiled_action_reader(data):
    ours = _world()
    with guarded():
        got = _accept(data, ours)
    if got == grid.NOT_PLAIN:
        assert all(not v.any() for v in ours.values())  # left to the parser, nothing applied
        return
    parsed = grid.parse_acts(data)
    assert isinstance(parsed, grid.Acts), parsed  # the compiled reader takes only what the parser takes
    ref = _world()
    ref["refused"] += accept_rows(parsed.rows, SLOTS, GROUPS, 0, True, ref["acted"], ref["acts"], ref["mark_floor"],
                                  ref["memory"])  # fmt: skip
    assert got == len(parsed.rows) - ref["refused"].sum()
    for name, value in ours.items():
        np.testing.assert_array_equal(value, ref[name], err_msg=name)


def _obs(seed: int, k: int, tick: int) -> bytes:
    rng = np.random.default_rng(seed)
    ints = rng.integers(0, 3, (k, grid.OBS_INTS))
    ints[:, 0] = rng.integers(-1, AGENTS + 1, k)
    return grid.observations(tick, ints, rng.random((k, PERC_F_LEN)))


SLOT_OF = np.arange(AGENTS, dtype=np.int64)


def _answer(data: bytes) -> tuple[int, np.ndarray, np.ndarray]:
    """The agent's reader and step on `data` for agents 0..AGENTS-1: (size, the message written, memories)."""
    mems, rows = new_memory(AGENTS), np.zeros((AGENTS, grid.ACT_ROW), np.int64)
    out, info = np.zeros(grid.ENVELOPE + AGENTS * grid.ACT_ROW * 8, np.uint8), np.zeros(3, np.int64)
    size = answer_message(KIND, data, mems, SLOT_OF, rows, PARAMS, np.int64(9), False, out, info)
    return size, out, mems


@FUZZ
@given(inputs(st.builds(_obs, st.integers(0, 2**32 - 1), st.integers(0, AGENTS), ticks)))
def test_the_agents_compiled_observation_reader(data):
    with guarded():
        size, out, mems = _answer(data)
    if size < 0:  # left to the parser, or malformed: nobody stepped
        assert size in (grid.NOT_PLAIN, -1) and (mems == new_memory(AGENTS)).all()
        return
    parsed = grid.parse_obs(data)
    assert isinstance(parsed, grid.Obs), parsed
    ref_mems, ref_rows = new_memory(AGENTS), np.zeros((AGENTS, grid.ACT_ROW), np.int64)
    n = answer_rows(KIND, parsed.ints.reshape(-1), parsed.pf.reshape(-1), ref_mems, SLOT_OF, ref_rows, PARAMS,
                    np.int64(9), parsed.tick, False)  # fmt: skip
    assert out[:size].tobytes() == grid.pack_actions(parsed.tick, ref_rows[:n])
    np.testing.assert_array_equal(mems, ref_mems)
