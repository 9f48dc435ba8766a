"""The grid's wire, without zenoh: messages round-trip, every bad row is refused
by reason and changes nothing, and the agent's batch step equals the engine's."""

import numpy as np

from agents.controllers.grid.dispatch import answer_rows, step_controller
from swarm.core import wire
from swarm.scenario import load_scenario
from world_server.grid.accept import (
    OBS_OVERHEAD,
    REFUSALS,
    accept_message,
    accept_messages,
    accept_rows,
    observe_rows,
    write_observations,
)
from world_server.grid.face import wire as proto
from world_server.grid.face.layout import (
    A_MARK,
    A_MOVE,
    ACT_LEN,
    MARK,
    MARK_NONE,
    controller_kind,
    controller_params,
    new_memory,
)
from world_server.grid.world import GridWorld

ACTIVE, FREE = 2, 0


def _world(agents=3, seed=5):
    scenario = load_scenario("setup2").with_overrides(agents=agents, seed=seed)
    return scenario, GridWorld(scenario)


def test_observation_rows_round_trip_and_equal_the_world_perception():
    _, w = _world()
    agents = np.array([2, 0], dtype=np.int64)
    ints = np.zeros((2, proto.OBS_INTS), np.int64)
    pf = np.zeros((2, 5))
    observe_rows(w.layers, w.pher, w.pheromone_on, w.base[0], w.base[1], w.pos, w.payload, w.blocked, agents, ints,
                 pf, False)  # fmt: skip
    obs = proto.parse_obs(proto.observations(7, ints, pf))
    assert isinstance(obs, proto.Obs) and obs.tick == 7
    assert obs.agents.tolist() == [2, 0]
    for i, a in enumerate(agents):
        pi, pfa = np.zeros(25, np.int64), np.zeros(5)
        w.perceive(int(a), pi, pfa)
        np.testing.assert_array_equal(obs.pi[i], pi)
        assert obs.cells[i] == w.pos[a, 0] * w.layers.shape[2] + w.pos[a, 1]
    assert obs.ints.flags.writeable and obs.ints.flags.c_contiguous


def test_malformed_observations_are_rejected_not_raised():
    good = proto.observations(1, np.zeros((1, proto.OBS_INTS), np.int64), np.zeros((1, 5)))
    assert isinstance(proto.parse_obs(good), proto.Obs)
    for bad in (b"", b"\x00\xff", wire.pack({"type": "obs", "tick": 1, "ints": b"123", "pf": b""}),
                wire.pack({"type": "obs", "tick": -1, "ints": b"", "pf": b""}),
                proto.observations(1, np.zeros((1, proto.OBS_INTS), np.int64), np.full((1, 5), np.nan)),
                proto.observations(1, np.zeros((2, proto.OBS_INTS), np.int64), np.zeros((1, 5)))):  # fmt: skip
        assert isinstance(proto.parse_obs(bad), wire.Rejected)
    memory = proto.parse_obs(proto.memory_message(np.array([3]), new_memory(1)))
    assert isinstance(memory, proto.Memory) and memory.rows[0, 0] == 3


def test_every_bad_row_is_refused_by_reason_and_changes_nothing():
    n = 4
    slots = np.array([ACTIVE, ACTIVE, FREE, ACTIVE], np.int64)
    group_ids = np.array([0, 1, -1, 0], np.int64)
    acts = np.zeros((n, ACT_LEN), np.int64)
    acted, memory = np.zeros(n, bool), np.zeros((n, 8), np.int64)
    mark_floor = np.array([0, 0, 0, 5], np.int64)  # agent 3 may write no mark below 5 on its cell
    stay = np.zeros(ACT_LEN, np.int64)
    stay[A_MOVE], stay[A_MARK] = 4, MARK_NONE
    wild = stay.copy()
    wild[A_MOVE] = 99
    low = stay.copy()
    low[A_MARK] = 4
    rows = proto.action_rows([0, 1, 2, 99, -1, 3, 3, 0], [stay, stay, stay, stay, stay, wild, low, stay],
                             [0, 0, 0, 0, 0, 0, 1, 0], np.arange(64).reshape(8, 8))  # fmt: skip
    refused = accept_rows(rows, slots, group_ids, 0, True, acted, acts, mark_floor, memory)
    counts = dict(zip(REFUSALS, refused.tolist(), strict=True))
    assert counts == {"act: unknown agent": 3, "act: names an agent of another process": 1,
                      "act: second action in one tick": 1, "act: out-of-range action": 1,
                      "act: a mark lower than UPDATE-VALUE allows": 1}  # fmt: skip
    assert acted.tolist() == [True, False, False, False]
    assert acts[0, A_MOVE] == 4 and acts[0, A_MARK] == MARK_NONE and not acts[1:].any()
    np.testing.assert_array_equal(memory[0], np.arange(8))  # the first row of agent 0, not the refused second
    assert not memory[1:].any()


def test_the_batch_answer_equals_the_engine_step_agent_by_agent():
    scenario, w = _world(agents=5, seed=9)
    kind, params = controller_kind(scenario.controller), controller_params(scenario)
    agents = np.arange(5, dtype=np.int64)
    ints, pf = np.zeros((5, proto.OBS_INTS), np.int64), np.zeros((5, 5))
    observe_rows(w.layers, w.pher, w.pheromone_on, w.base[0], w.base[1], w.pos, w.payload, w.blocked, agents, ints,
                 pf, False)  # fmt: skip
    blocks = proto.obs_blocks(proto.observations(12, ints, pf))
    ints_ro, pf_ro = np.frombuffer(blocks.ints, "<i8"), np.frombuffer(blocks.pf, "<f8")
    mems, out = new_memory(4), np.zeros((4, proto.ACT_ROW), np.int64)
    slot_of = np.array([3, 2, -1, 1, 0], np.int64)  # agent 2 is not ours
    seed = np.int64(scenario.seed)
    n = answer_rows(kind, ints_ro, pf_ro, mems, slot_of, out, params, seed, 12, False)
    assert n == 4 and out[:n, proto.R_AGENT].tolist() == [0, 1, 3, 4]
    for row, agent in zip(out[:n], (0, 1, 3, 4), strict=True):
        mem, act = new_memory(1)[0], np.zeros(ACT_LEN, np.int64)
        pi = ints[agent, proto.OBS_PERCEPTION :]
        step_controller(kind, pi, pf[agent], mem, act, params, seed, agent, 12)
        np.testing.assert_array_equal(row[proto.R_ACT : proto.R_ACT + ACT_LEN], act)
        np.testing.assert_array_equal(row[proto.R_MEM :], mem)
        np.testing.assert_array_equal(mems[slot_of[agent]], mem)
        lowers = act[A_MARK] != MARK_NONE and act[A_MARK] < ints[agent, proto.OBS_PERCEPTION + MARK]
        assert row[proto.R_MARKED] == int(lowers)
    # blocks that disagree, or a float that is not finite: refused whole, nothing stepped
    before = mems.copy()
    assert answer_rows(kind, ints_ro[:-1], pf_ro, mems, slot_of, out, params, seed, 12, False) == -1
    bad = pf.copy()
    bad[3, 0] = np.nan
    bad_ro = np.frombuffer(bad.tobytes(), "<f8")  # read-only, as a message's block (one compiled signature)
    assert answer_rows(kind, ints_ro, bad_ro, mems, slot_of, out, params, seed, 12, False) == -1
    np.testing.assert_array_equal(mems, before)
    # the null floor answers STAY for ours and leaves the memory alone
    assert answer_rows(kind, ints_ro, pf_ro, mems, slot_of, out, params, seed, 13, True) == 4
    assert (out[:4, proto.R_ACT + A_MOVE] == 4).all()
    np.testing.assert_array_equal(mems, before)


def _answer(message: bytes, kind, params, count=5):
    from agents.controllers.grid.envelope import answer_message

    mems, rows = new_memory(count), np.zeros((count, proto.ACT_ROW), np.int64)
    out, info = np.zeros(proto.ENVELOPE + count * proto.ACT_ROW * 8, np.uint8), np.zeros(3, np.int64)
    size = answer_message(kind, message, mems, np.arange(count, dtype=np.int64), rows,
                          params, np.int64(9), False, out, info)  # fmt: skip
    return size, out[: max(size, 0)].tobytes(), rows, mems, info


def test_the_compiled_envelope_writes_the_action_message_byte_for_byte():
    """The agent's one-call answer (agents/controllers/grid/envelope.py) equals parse, step and pack_actions."""
    scenario, w = _world(agents=5, seed=9)
    kind, params = controller_kind(scenario.controller), controller_params(scenario)
    ints, pf = np.zeros((5, proto.OBS_INTS), np.int64), np.zeros((5, 5))
    observe_rows(w.layers, w.pher, w.pheromone_on, w.base[0], w.base[1], w.pos, w.payload, w.blocked,
                 np.arange(5, dtype=np.int64), ints, pf, False)  # fmt: skip
    for tick in (0, 127, 128, 300, 70_000, 2**33):  # every msgpack width of the tick
        message = proto.observations(tick, ints, pf)
        size, written, _, mems, info = _answer(message, kind, params)
        blocks = proto.obs_blocks(message)
        ref_mems, ref_rows = new_memory(5), np.zeros((5, proto.ACT_ROW), np.int64)
        n = answer_rows(kind, np.frombuffer(blocks.ints, "<i8"), np.frombuffer(blocks.pf, "<f8"), ref_mems,
                        np.arange(5, dtype=np.int64), ref_rows, params, np.int64(9), tick, False)  # fmt: skip
        assert written == proto.pack_actions(tick, ref_rows[:n]) and size == len(written)
        assert info.tolist() == [n, int(ref_rows[:n, proto.R_MARKED].any()), tick]
        np.testing.assert_array_equal(mems, ref_mems)


def test_the_compiled_envelope_leaves_every_other_message_to_the_parser():
    scenario, _ = _world(agents=5, seed=9)
    kind, params = controller_kind(scenario.controller), controller_params(scenario)
    good = proto.observations(4, np.zeros((5, proto.OBS_INTS), np.int64), np.zeros((5, 5)))
    others = [wire.stop_message("done"), wire.pack({"type": "wake"}), proto.memory_message(np.zeros(1, np.int64),
              new_memory(1)), b"", b"\x85", wire.pack({"type": "obs", "ints": b"", "pf": b"", "tick": 4})]  # fmt: skip
    others += [good[:k] for k in range(0, len(good), 7)]  # every truncation: never a read past the end
    others += [good + b"\x00"]
    for message in others:
        assert _answer(message, kind, params)[0] == proto.NOT_PLAIN, message[:40]
    lying = bytearray(good)
    lying[lying.index(b"ints") + 5] = 0xFF  # a bin length past the end
    assert _answer(bytes(lying), kind, params)[0] == proto.NOT_PLAIN
    nan = proto.observations(4, np.zeros((5, proto.OBS_INTS), np.int64), np.full((5, 5), np.nan))
    size, _, _, mems, _ = _answer(nan, kind, params)
    assert size == -1 and (mems == new_memory(5)).all()  # a plain observation that is malformed: nobody stepped


def _accept_world():
    n = 4
    return {"slots": np.array([ACTIVE, ACTIVE, FREE, ACTIVE], np.int64), "group_ids": np.array([0, 1, -1, 0], np.int64),
            "acted": np.zeros(n, bool), "acts": np.zeros((n, ACT_LEN), np.int64), "mark_floor": np.zeros(n, np.int64),
            "memory": np.zeros((n, 8), np.int64)}  # fmt: skip


def _mixed_rows():
    """Good rows and one of every refusal: unknown agents, another process's, a second action, out of range."""
    stay = np.zeros(ACT_LEN, np.int64)
    stay[A_MOVE] = 4
    wild = stay.copy()
    wild[A_MOVE] = 99
    return proto.action_rows([0, 1, 2, 99, -1, 3, 0, 3], [stay, stay, stay, stay, stay, wild, stay, stay],
                             [0, 0, 0, 0, 0, 0, 0, 1], np.arange(64).reshape(8, 8))  # fmt: skip


def _accept(message, first, last, w):
    refused = np.full(len(REFUSALS), 7, np.int64)
    got = accept_message(np.frombuffer(message, np.uint8), first, last, w["slots"], w["group_ids"], 0, True,
                         w["acted"], w["acts"], w["mark_floor"], w["memory"], refused)  # fmt: skip
    return got, refused


def test_the_world_accepts_a_plain_action_message_in_one_call_as_the_parser_does():
    """grid_wire.accept_message on pack_actions' bytes equals parse_acts then accept_rows (every width of the tick)."""
    rows = _mixed_rows()
    for tick in (0, 127, 128, 300, 70_000, 2**33):
        message = proto.pack_actions(tick, rows)
        ours, ref = _accept_world(), _accept_world()
        got, refused = _accept(message, tick, tick, ours)
        parsed = proto.parse_acts(message)
        expected = accept_rows(parsed.rows, ref["slots"], ref["group_ids"], 0, True, ref["acted"], ref["acts"],
                               ref["mark_floor"], ref["memory"])  # fmt: skip
        assert got == 2 and expected.sum() == 6 and (refused - 7).tolist() == expected.tolist()  # refusals added up
        for name in ours:
            np.testing.assert_array_equal(ours[name], ref[name], err_msg=name)
        assert ours["acts"][:, A_MARK].tolist() == [0, 0, 0, 0]  # the rows' mark writes (0), kept to be applied


def test_the_world_leaves_every_other_action_message_to_the_parser_and_changes_nothing():
    good = proto.pack_actions(300, _mixed_rows())
    others = [b"", b"\x85", wire.pack({"type": "act", "tick": 300, "family": "grid", "rows": b""}),  # another order
              good + b"\x00", wire.pack({"type": "wake"}),
              wire.pack({"v": wire.VERSION, "type": "act", "family": "arena", "tick": 300, "rows": b""})]  # fmt: skip
    others += [good[:k] for k in range(0, len(good), 5)]  # every truncation: never a read past the end
    lying = bytearray(good)
    lying[lying.index(b"rows") + 5] = 0xFF  # a bin length past the end
    odd = bytearray(proto.pack_actions(300, _mixed_rows()[:1]))
    odd[odd.index(b"rows") + 5] -= 8  # rows not a whole number of rows
    others += [bytes(lying), bytes(odd[:-8])]
    for message in others:
        w = _accept_world()
        assert _accept(message, 300, 300, w)[0] == proto.NOT_PLAIN, message[:40]
        assert not (w["acted"].any() or w["acts"].any() or w["memory"].any())
    for first, last in ((301, 301), (299, 299), (301, 303)):  # not for this tick (lock-step, or real time's window)
        w = _accept_world()
        assert _accept(good, first, last, w)[0] == proto.NOT_PLAIN and not w["acted"].any()
    assert _accept(good, 298, 300, _accept_world())[0] == 2  # real time: one of the last three ticks
    big = proto.pack_actions(300, np.zeros((wire.MAX_MESSAGE_BYTES // (8 * proto.ACT_ROW) + 1, proto.ACT_ROW), int))
    assert _accept(big, 300, 300, _accept_world())[0] == proto.NOT_PLAIN  # too large: the parser refuses it


def test_the_world_writes_every_observation_message_byte_for_byte_in_one_call():
    """grid_wire.write_observations equals the face's wire.observations per process: every width of the
    tick, blocks of one to 40 rows (bin 8 and bin 16), read back by the agent's parser."""
    rng = np.random.default_rng(3)
    sizes = [1, 3, 40, 2]
    ints = rng.integers(-(2**40), 2**40, size=(sum(sizes), proto.OBS_INTS))
    pf = rng.normal(size=(sum(sizes), 5))
    bounds = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    for tick in (0, 127, 128, 300, 70_000, 2**33):
        out = np.empty(len(sizes) * OBS_OVERHEAD + ints.nbytes + pf.nbytes, np.uint8)
        offsets = np.empty(len(sizes) + 1, np.int64)
        end = write_observations(tick, ints, pf, bounds, out, offsets)
        assert offsets[0] == 0 and offsets[-1] == end <= len(out)
        for g in range(len(sizes)):
            a, b = bounds[g], bounds[g + 1]
            assert out[offsets[g] : offsets[g + 1]].tobytes() == proto.observations(tick, ints[a:b], pf[a:b])


def test_the_world_applies_the_messages_of_a_tick_in_one_call_as_one_by_one():
    """grid_wire.accept_messages over messages laid end to end equals accept_message on each in order, other
    messages (a late tick, another layout) left to the parser (NOT_PLAIN) and nothing of them applied."""
    stay = np.zeros(ACT_LEN, np.int64)
    stay[A_MOVE] = 4
    first = proto.pack_actions(300, proto.action_rows([0], [stay], [0], np.ones((1, 8), np.int64)))
    again = proto.pack_actions(300, proto.action_rows([0, 3], [stay, stay], [0, 1], np.full((2, 8), 5)))
    late = proto.pack_actions(299, proto.action_rows([1], [stay], [0], np.ones((1, 8), np.int64)))
    foreign = proto.pack_actions(300, proto.action_rows([1], [stay], [0], np.ones((1, 8), np.int64)))
    messages, groups = [first, late, b"\x85", again, foreign], [0, 1, 0, 0, 1]
    ours, ref = _accept_world(), _accept_world()
    refused, ref_refused = np.zeros(len(REFUSALS), np.int64), np.zeros(len(REFUSALS), np.int64)
    status = np.zeros(len(messages), np.int64)
    starts = np.concatenate([[0], np.cumsum([len(m) for m in messages])]).astype(np.int64)
    total = accept_messages(np.frombuffer(b"".join(messages), np.uint8), starts, np.array(groups, np.int64), 300, 300,
                            ours["slots"], ours["group_ids"], True, ours["acted"], ours["acts"], ours["mark_floor"],
                            ours["memory"], refused, status)  # fmt: skip
    expected = [accept_message(np.frombuffer(m, np.uint8), 300, 300, ref["slots"], ref["group_ids"], g, True,
                               ref["acted"], ref["acts"], ref["mark_floor"], ref["memory"], ref_refused)
                for m, g in zip(messages, groups, strict=True)]  # fmt: skip
    assert status.tolist() == expected == [1, proto.NOT_PLAIN, proto.NOT_PLAIN, 1, 1] and total == 3
    assert refused.tolist() == ref_refused.tolist() == [0, 0, 1, 0, 0]  # agent 0's second action
    for name in ours:
        np.testing.assert_array_equal(ours[name], ref[name], err_msg=name)
    assert ours["acted"].tolist() == [True, True, False, True] and ours["memory"][1].tolist() == [1] * 8


def test_the_mark_floor_is_update_value_on_the_agents_cell():
    """grid_wire.mark_floors: a cell's mark, or one more than its lowest free neighbour's (obstacles and the
    grid's edge not counted), from the perception rows the world sends: what an honest mark write can be."""
    from world_server.grid.accept import mark_floors, observe_rows
    from world_server.grid.world import L_MARK, L_OBST

    layers = np.zeros((8, 3, 4), np.int64)
    layers[L_MARK] = [[MARK_NONE, 7, 3, 9], [6, MARK_NONE, 8, 2], [MARK_NONE, MARK_NONE, MARK_NONE, MARK_NONE]]
    layers[L_OBST, 1, 3] = 1  # the 2 beside (0, 3) is behind an obstacle
    pos = np.array([[0, 0], [0, 3], [2, 2], [1, 1], [2, 0]], np.int64)
    floors, agents = np.full(5, -1, np.int64), np.array([0, 1, 2, 3], np.int64)
    ints, pf = np.zeros((4, proto.OBS_INTS), np.int64), np.zeros((4, 5))
    observe_rows(layers, np.zeros((3, 4)), False, 0, 0, pos, np.zeros(5, np.int64), np.zeros(5, np.int64), agents, ints,
                 pf, False)  # fmt: skip
    mark_floors(ints, agents, floors)
    assert floors.tolist() == [7, 4, 9, 7, -1]  # agent 4 not asked for
