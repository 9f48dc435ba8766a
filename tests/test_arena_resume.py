"""What an exact arena resume rests on: physics checkpoints, controllers'
memory as bytes, and the wire that carries it (the kill -9 runs themselves
are in test_arena_distributed.py)."""

import tracemalloc
from dataclasses import replace

import msgpack
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from agents.arena_runtime import give_back
from agents.controllers import CONTROLLERS
from agents.controllers.arena import make_controller
from swarm.core import memory_codec, msgpack_views
from swarm.core.wire import Rejected, pack
from swarm.engines.arena import ArenaEngine
from swarm.scenario import load_scenario
from tests.arena_helpers import arena
from world_server.arena.face import wire as arena_proto
from world_server.arena.scenario import controller_params
from world_server.arena.strips import owners
from world_server.arena.world import ArenaWorld

CROWD = arena('[[group]]\ncount = 12\ncontroller = "wander"\n', w=0.8, h=0.8, max_ticks=100_000)


def _push(world: ArenaWorld, ticks: range) -> None:
    """Every robot drives at a speed drawn per 20 ticks: they bump into each other and the walls."""
    for t in ticks:
        world.apply(np.random.default_rng(t // 20).uniform(0.02, 0.12, (world.n, 2)))


@pytest.mark.parametrize(("at", "strips"), [(50, 1), (150, 1), (50, 2), (150, 2)])
def test_a_world_restored_from_a_checkpoint_goes_on_bit_for_bit_with_robots_in_contact(at, strips):
    crowd = replace(CROWD, physics_strips=strips)  # two: robots cross the edge at x = 0.4 and touch across it
    a = ArenaWorld(crowd)
    _push(a, range(at))
    saved = a.checkpointed
    assert a.tick % CROWD.checkpoint == 0 and saved is not None and len(saved["contacts_f"]) > 0
    if strips > 1:  # some saved contact is a robot's with another strip's robot, its ghost there
        robot = saved["contacts_i"][:, :2] - a.bodies.strips[0].walls
        owner = owners(saved["pose"][:, 0], a.bodies.edges)
        ghost = (robot >= 0) & (owner[np.clip(robot, 0, a.n - 1)] != saved["contacts_strip"][:, None])
        assert ghost.any()
    b = ArenaWorld(crowd, parked=True)  # as a restarted world server builds it
    b.restore(saved)
    _push(a, range(at, 3 * at))
    _push(b, range(at, 3 * at))
    np.testing.assert_array_equal(a.pose, b.pose)
    np.testing.assert_array_equal(a.bodies.collisions, b.bodies.collisions)  # touching pairs are not new collisions
    assert a.bodies.collisions.sum() > 20


@pytest.mark.parametrize("strips", [1, 2])
def test_saved_contacts_are_what_keeps_collision_counts(strips):
    crowd = replace(CROWD, physics_strips=strips)
    a = ArenaWorld(crowd)
    _push(a, range(50))
    saved = {k: v for k, v in a.checkpointed.items() if not k.startswith("contacts")}
    saved["space_clock"] = a.checkpointed["space_clock"]
    b = ArenaWorld(crowd, parked=True)
    b.restore({**saved, "contacts_f": np.zeros((0, 28)), "contacts_i": np.zeros((0, 6), np.int64),
               "contacts_h": np.zeros((0, 2), np.uint64), "contacts_strip": np.zeros(0, np.int64)})  # fmt: skip
    _push(a, range(50, 60))
    _push(b, range(50, 60))
    assert b.bodies.collisions.sum() > a.bodies.collisions.sum()  # without them, contacts begin again


def test_memory_codec_round_trips_exactly():
    memory = {"tick": 7, 3: [1.5, float("nan"), None, True], "fields": {"M_N": np.linspace(0, 1, 12).reshape(3, 4)},
              "counts": np.arange(5, dtype=np.int64), "mask": np.array([True, False]),
              "grey": np.arange(3, dtype=np.uint8),
              "f32": np.float32(0.1), "i": np.int64(2**40), "pair": (1, 2)}  # fmt: skip
    back = memory_codec.decode(memory_codec.encode(memory))
    assert back["tick"] == 7 and back[3][0] == 1.5 and np.isnan(back[3][1]) and back[3][2:] == [None, True]
    for key in ("counts", "mask", "grey"):
        assert back[key].dtype == memory[key].dtype
        np.testing.assert_array_equal(back[key], memory[key])
    np.testing.assert_array_equal(back["fields"]["M_N"], memory["fields"]["M_N"])
    assert back["fields"]["M_N"].flags.writeable and back["pair"] == [1, 2] and back["i"] == 2**40


def _as_msgpack_packs(value):
    """The wire form by its definition: msgpack with each array as extension 1 of [dtype, shape, bytes]."""
    if isinstance(value, np.ndarray):
        return msgpack.ExtType(1, msgpack.packb([value.dtype.str, list(value.shape), value.tobytes()]))
    return memory_codec._plain(value)


_ARRAYS = st.sampled_from(["<f4", "<f8", "<i8", "|u1", "|b1"]).flatmap(
    lambda kind: st.integers(0, 70_000).map(lambda n: np.arange(n).astype(kind))
)
_LEAVES = (
    st.none()
    | st.booleans()
    | st.integers(-(2**63), 2**64 - 1)
    | st.floats()
    | st.text(max_size=300)
    | st.binary(max_size=300)
    | _ARRAYS
    | st.sampled_from([np.float32(0.1), np.int64(-5), np.bool_(True)])
)
_MEMORIES = st.recursive(
    _LEAVES,
    lambda inner: (
        st.lists(inner, max_size=20)
        | st.tuples(inner, inner)
        | st.dictionaries(st.text(max_size=5) | st.integers(-3, 3), inner, max_size=20)
    ),
    max_leaves=40,
)


@settings(max_examples=150, deadline=None)
@given(_MEMORIES)
def test_a_memory_written_in_pieces_is_msgpacks_own_form_byte_for_byte(memory):
    """Headers at every size boundary (fixext, ext8/16/32, bin8/16/32, maps and arrays past 15) included."""
    assert memory_codec.encode(memory) == msgpack.packb(memory, default=_as_msgpack_packs, use_bin_type=True)


def test_every_extension_and_bin_header_size_is_msgpacks():
    for n in [*range(40), *range(240, 270), *range(65_500, 65_560)]:
        memory = {"a": np.zeros(n, np.uint8), "b": b"x" * n}
        assert memory_codec.encode(memory) == msgpack.packb(memory, default=_as_msgpack_packs, use_bin_type=True), n


def test_an_action_message_written_from_pieces_equals_the_one_packed_from_its_blob():
    memory = {"fields": {"u0": np.random.default_rng(1).random((16, 300)).astype(np.float32)}, "tick": 9}
    wheels, shared = np.ones((2, 3)), [(4, "map", b"nodes")]
    from_pieces = arena_proto.actions(7, [4, 5], wheels, shared, [(4, memory_codec.pieces(memory)), (5, b"\x80")])
    from_blob = arena_proto.actions(7, [4, 5], wheels, shared, [(4, memory_codec.encode(memory)), (5, b"\x80")])
    assert from_pieces == from_blob
    assert arena_proto.parse_acts(from_pieces).memory == [(4, memory_codec.encode(memory)), (5, b"\x80")]


def test_a_save_ticks_message_copies_the_memorys_arrays_once():
    """The agent process's peak at a save tick: the fields go straight into the message,
    not through a snapshot copy, a blob and a second packing (3.1 times their size before)."""
    fields = {f"u{g}": np.random.default_rng(g).random((8, 210 * 210)).astype(np.float32) for g in range(2)}
    size = sum(a.nbytes for a in fields.values())
    tracemalloc.start()
    payload = arena_proto.actions(1, [0], np.zeros((1, 2)), memory=[(0, memory_codec.pieces({"fields": fields}))])
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert len(payload) > size and peak < 1.05 * size


@pytest.mark.parametrize("blob", [
    b"\xc1garbage",
    msgpack.packb(msgpack.ExtType(9, b"x")),
    msgpack.packb(msgpack.ExtType(1, msgpack.packb(["|O", [1], b"12345678"]))),
    msgpack.packb(msgpack.ExtType(1, msgpack.packb(["<f8", [3], b"short"]))),
    "not bytes",
])  # fmt: skip
def test_a_broken_memory_is_a_reason_not_a_traceback(blob):
    assert isinstance(memory_codec.decode(blob), Rejected)


@pytest.mark.parametrize("controller", CONTROLLERS.names(lambda c: c.world == "arena"))
def test_a_controller_given_back_its_memory_through_the_codec_steps_on_as_before(controller):
    scenario = load_scenario(CONTROLLERS[controller].example).with_overrides(controller=controller, max_ticks=200)
    engine = ArenaEngine(scenario)
    engine.step(60)
    twin = make_controller(controller)
    twin.reset(scenario.seed, 0, controller_params(scenario, 0))
    assert give_back(twin, memory_codec.encode(engine.controllers[0].snapshot()))
    readings = engine.world.perceive()[0]
    np.testing.assert_array_equal(np.asarray(twin.step(readings)), np.asarray(engine.controllers[0].step(readings)))


@pytest.mark.parametrize("controller", ["carrot", "dft"])
def test_a_memory_that_does_not_fit_its_controller_is_refused_and_changes_nothing(controller):
    scenario = load_scenario("zmaze").with_overrides(controller=controller, max_ticks=100)
    engine = ArenaEngine(scenario)
    engine.step(5)
    brain = engine.controllers[0]
    before = memory_codec.encode(brain.snapshot())
    assert not give_back(brain, memory_codec.encode({"nothing": 1}))
    assert not give_back(brain, b"\x00\x01")
    if controller == "dft":  # fails half-way: the first fields written over, then one is missing
        other = memory_codec.decode(before)
        other["fields"] = {k: v + 1 for k, v in other["fields"].items() if k != "img1"}
        assert not give_back(brain, memory_codec.encode(other))
    assert memory_codec.encode(brain.snapshot()) == before


def test_a_dft_robot_takes_its_memory_back_without_a_rollback_copy():
    """A resume's peak: the DFT controller checks a memory whole before writing it, so the agent
    keeps no copy of the old state to roll back to; the decoded arrays are written in place, not copied."""
    from agents.arena_runtime import restore_or_keep

    scenario = load_scenario("large-maze").with_overrides(controller="dft", max_ticks=50)
    engine = ArenaEngine(scenario)
    engine.step(3)
    blob = memory_codec.encode(engine.controllers[0].snapshot())
    twin = make_controller("dft")
    twin.reset(scenario.seed, 0, controller_params(scenario, 0))
    memory = memory_codec.decode(blob)
    tracemalloc.start()
    assert restore_or_keep(twin, memory)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert len(blob) > 2_000_000 and peak < 0.05 * len(blob)  # the rollback copy alone would be len(blob)
    assert memory_codec.encode(twin.snapshot()) == blob
    broken = memory_codec.decode(blob)
    last = sorted(broken["fields"])[-1]
    broken["fields"] = {k: v + 1 for k, v in broken["fields"].items() if k != last}  # fails at the last group
    assert not restore_or_keep(twin, broken)
    assert memory_codec.encode(twin.snapshot()) == blob  # nothing written


def test_a_dft_memory_whose_sensed_context_does_not_fit_changes_nothing():
    from dataclasses import replace

    from agents.arena_runtime import restore_or_keep

    s = load_scenario("zmaze").with_overrides(controller="dft", max_ticks=50)
    engine = ArenaEngine(replace(s, controller_params={"dft": {"obstacles": "sensed"}}))
    engine.step(20)
    brain = engine.controllers[0]
    before = memory_codec.encode(brain.snapshot())
    broken = memory_codec.decode(before)
    assert broken["context"] is not None
    broken["tick"] += 5
    broken["fields"] = {k: v + 1 for k, v in broken["fields"].items()}
    broken["context"]["marked"] = [1]  # the context is checked last: fields and tick would be written first
    assert not restore_or_keep(brain, broken)
    assert memory_codec.encode(brain.snapshot()) == before


def test_actions_carry_memory_only_for_their_own_agents():
    wheels = np.zeros((2, 2))
    ok = arena_proto.parse_acts(arena_proto.actions(5, [1, 2], wheels, memory=[(2, b"abc")]))
    assert ok.memory == [(2, b"abc")]
    stray = arena_proto.parse_acts(arena_proto.actions(5, [1, 2], wheels, memory=[(3, b"abc")]))
    assert isinstance(stray, Rejected) and "does not act for" in stray.reason
    bad = pack({"type": "act", "family": "arena", "tick": 5, "agents": [1], "wheels": bytes(16), "memory": [[1, "x"]]})
    assert isinstance(arena_proto.parse_acts(bad), Rejected)
    obs = arena_proto.parse_obs(arena_proto.observations(5, [1], [{}], keep=True))
    assert obs.keep and not arena_proto.parse_obs(arena_proto.observations(5, [1], [{}])).keep
    back = arena_proto.parse_obs(arena_proto.memory_message([(1, b"m")]))
    assert isinstance(back, arena_proto.ArenaMemory) and back.memory == [(1, b"m")]


def test_the_checkpoint_is_a_scenario_key_with_a_range():
    from swarm.core.errors import ScenarioError
    from swarm.scenario import parse_scenario_text
    from tests.arena_helpers import box

    assert arena("[[group]]\ncount = 1\n").checkpoint == 50
    with pytest.raises(ScenarioError) as err:
        parse_scenario_text("checkpoint = 0\n" + box("[[group]]\ncount = 1\n"), "bad.toml")
    assert err.value.where == "checkpoint"


def test_the_publication_history_keeps_what_came_before_the_save_and_survives_a_cut_record(tmp_path):
    from world_server.history import SharedHistory

    path = tmp_path / "run.arena.shared.msgpack"
    h = SharedHistory(path)
    h.open(keep_before=None)
    for tick in range(6):
        h.add(tick, "map", tick % 2, bytes([tick]))
    h.close()
    path.write_bytes(path.read_bytes() + msgpack.packb([6, "map", 0, b"cut short"])[:-4])  # a kill mid-write
    resumed = SharedHistory(path)
    resumed.open(keep_before=4)  # saved at tick 5: ticks 4 on are published again
    assert resumed.of("map") == [(0, [b"\x00", b"\x02"]), (1, [b"\x01", b"\x03"])] and resumed.of("context") == []
    resumed.add(4, "map", 0, b"\x04")
    resumed.close()
    again = SharedHistory(path)
    again.open(keep_before=100)
    assert again.of("map")[0] == (0, [b"\x00", b"\x02", b"\x04"])
    again.close()


HEAP_CHILD = """
import numpy as np
from swarm.core import heap

def rss_mb():
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith("VmRSS")) / 1024

big = np.ones(4 << 20, np.uint8)
del big  # glibc now raises its mmap threshold to 4 MB: smaller blocks come from the heap
blocks = [np.ones(1 << 20, np.uint8) for _ in range(40)]
above = np.ones(200_000, np.uint8)  # so freeing the blocks cannot simply lower the heap's top
del blocks
before = rss_mb()
print(heap._trim() is not None, heap.give_back(), before, rss_mb())
"""


def test_freed_heap_memory_goes_back_to_the_system():
    """swarm.core.heap: what an agent process packed for a save and freed is not kept by glibc's heap
    (in a fresh process: a test process's heap is full of holes the blocks would fall into)."""
    import subprocess
    import sys

    if not sys.platform.startswith("linux"):
        pytest.skip("reads /proc")
    out = subprocess.run([sys.executable, "-c", HEAP_CHILD], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr[-2000:]
    glibc, trimmed, before, now = out.stdout.split()
    if glibc != "True":
        pytest.skip("not glibc: nothing to give back this way")
    assert trimmed == "True" and float(now) < float(before) - 30, out.stdout


def _no_views(value):
    """A value read by msgpack_views with its bins as bytes, as msgpack reads them."""
    if isinstance(value, memoryview):
        return bytes(value)
    if isinstance(value, list):
        return [_no_views(v) for v in value]
    if isinstance(value, dict):
        return {k: _no_views(v) for k, v in value.items()}
    return value


_SIZES = [0, 1, 15, 16, 31, 32, 255, 256, 65_535, 65_536]
_KEYS = st.text(max_size=5) | st.integers(-3, 3) | st.binary(max_size=3)
_PLAIN = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-(2**63), 2**64 - 1)
    | st.floats(allow_nan=False, width=32)
    | st.text()
    | st.binary()
    | st.sampled_from(_SIZES).map(lambda n: "é" * n)
    | st.sampled_from(_SIZES).map(bytes),
    lambda inner: st.lists(inner) | st.dictionaries(_KEYS, inner),
    max_leaves=40,
)


@settings(max_examples=200, deadline=None)
@given(_PLAIN, st.booleans())
def test_msgpack_views_reads_what_msgpack_reads_with_bins_as_views_of_the_message(value, single):
    data = msgpack.packb(value, use_bin_type=True, use_single_float=single)
    got = msgpack_views.unpack(data)
    assert _no_views(got) == msgpack.unpackb(data, raw=False, strict_map_key=False)


def test_msgpack_views_reads_every_header_size_and_leaves_bins_where_they_lie():
    for n in _SIZES:
        value = {"s": "x" * n, "b": b"y" * n, "a": [0] * n, "m": {i: None for i in range(n)}, -n: 2**64 - 1 - n}
        data = msgpack.packb(value, use_bin_type=True)
        got = msgpack_views.unpack(data)
        assert _no_views(got) == value
        assert isinstance(got["b"], memoryview) and got["b"].obj is data and got["b"].readonly  # no copy


def _same_as_msgpack(data: bytes) -> None:
    def theirs(code, raw):
        return ("ext", code, raw)

    try:
        want = msgpack.packb(msgpack.unpackb(data, raw=False, strict_map_key=False, ext_hook=theirs))
    except Exception:
        want = "refused"
    try:
        got = msgpack.packb(_no_views(msgpack_views.unpack(data, lambda code, raw: ("ext", code, bytes(raw)))))
    except ValueError as err:
        got = "refused" if want == "refused" or "too deep" not in str(err) else want  # msgpack nests to 1024
    assert got == want, data.hex()


@settings(max_examples=500, deadline=None)
@given(st.binary(max_size=120))
@example(b"\xd4\xff\x00")  # msgpack's Timestamp extension, one byte long: malformed
@example(b"\xd6\xff\x00\x00\x00\x05")  # ... four bytes: 5 s
def test_msgpack_views_refuses_what_msgpack_refuses_with_a_value_error(data):
    """Random bytes (NaNs compared by their packed form): read alike, or refused by both, never another error."""
    _same_as_msgpack(data)


@settings(max_examples=200, deadline=None)
@given(_PLAIN, st.data())
def test_msgpack_views_refuses_a_truncated_or_overlong_message(value, data):
    packed = msgpack.packb(value, use_bin_type=True)
    cut = data.draw(st.integers(0, len(packed) - 1))
    _same_as_msgpack(packed[:cut])
    _same_as_msgpack(packed + b"\xc0")
    deep = b"\x91" * (msgpack_views.MAX_DEPTH + 1) + b"\xc0"
    with pytest.raises(ValueError, match="too deep"):
        msgpack_views.unpack(deep)


@settings(max_examples=100, deadline=None)
@given(_MEMORIES)
def test_a_memory_decoded_with_views_equals_the_one_decoded_with_copies(memory):
    blob = memory_codec.encode(memory)
    copied, viewed = memory_codec.decode(blob), memory_codec.decode(blob, views=True)
    assert memory_codec.encode(_no_views(viewed)) == memory_codec.encode(copied) == blob
    arrays = [v for v in _leaves(viewed) if isinstance(v, np.ndarray)]
    assert all(not a.flags.writeable and not a.flags.owndata for a in arrays)  # views of the blob, not copies


def _leaves(value):
    if isinstance(value, list):
        return [x for v in value for x in _leaves(v)]
    if isinstance(value, dict):
        return [x for v in value.values() for x in _leaves(v)]
    return [value]


def test_broken_array_extensions_are_refused_with_views_as_with_copies():
    good = memory_codec.encode({"a": np.arange(4.0)})
    cases = [
        msgpack.packb({"a": msgpack.ExtType(1, msgpack.packb(["<f8", [5], bytes(32)]))}),  # bytes short of the shape
        msgpack.packb({"a": msgpack.ExtType(1, msgpack.packb(["<f8", [-4], bytes(32)]))}),
        msgpack.packb({"a": msgpack.ExtType(1, msgpack.packb(["|O", [1], bytes(8)]))}),
        msgpack.packb({"a": msgpack.ExtType(1, msgpack.packb(["<f8", [4], "x" * 32]))}),
        msgpack.packb({"a": msgpack.ExtType(2, b"")}),
        good[:-1],
    ]
    for blob in cases:
        assert isinstance(memory_codec.decode(blob), Rejected) and isinstance(memory_codec.decode(blob, True), Rejected)


def test_a_dft_memory_handed_back_is_read_where_it_lies_in_the_message():
    """A resume's peak: the memory message is parsed with its blob as a view, the blob decoded
    with its fields as views, and the controller copies them into its own arrays: no MB-sized copy on the way."""
    from agents.arena_runtime import ArenaAgentRuntime
    from agents.controllers.arena import StepGuard

    scenario = load_scenario("large-maze").with_overrides(controller="dft", max_ticks=50)
    engine = ArenaEngine(scenario)
    engine.step(3)
    blob = memory_codec.encode(engine.controllers[0].snapshot())
    message = arena_proto.memory_message([(0, blob)])
    runtime = ArenaAgentRuntime.__new__(ArenaAgentRuntime)  # its restore path alone, without a session
    runtime.brains, runtime.slot_of, runtime.refused_memory = [make_controller("dft")], {0: 0}, 0
    runtime.guard, runtime.names = StepGuard(), ["dft"]
    runtime.brains[0].reset(scenario.seed, 0, controller_params(scenario, 0))
    tracemalloc.start()
    handed = arena_proto.parse_obs(message)
    assert isinstance(handed, arena_proto.ArenaMemory) and isinstance(handed.memory[0][1], memoryview)
    runtime._restore(handed)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert len(blob) > 2_000_000 and peak < 0.05 * len(blob) and runtime.refused_memory == 0  # a copy: len(blob)
    assert memory_codec.encode(runtime.brains[0].snapshot()) == blob
    reordered = pack({"memory": [[0, blob]], "type": "memory", "family": "arena"})  # not as memory_message writes
    assert arena_proto.parse_obs(reordered).memory == [(0, blob)]  # read with copies: still the same memory
