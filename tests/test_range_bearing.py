"""The range-and-bearing sensor: who is heard, where, what they said a tick ago, in both runtimes."""

import math

import numpy as np
import pytest

from agents.controllers.arena import broadcasts
from swarm.core.errors import ScenarioError
from swarm.engines.arena import ArenaEngine
from tests.arena_helpers import arena
from world_server.arena.face import wire as arena_proto
from world_server.arena.face.sensors import range_bearing
from world_server.arena.scenario import controller_params
from world_server.arena.world import ArenaWorld

# robot 0 at the centre facing +x; 1 ahead (0.1 m), 2 to its left (0.2 m), 3 behind on its right (0.283 m)
STARTS = [[0.5, 0.5, 0.0], [0.6, 0.5, 0.0], [0.5, 0.7, 1.0], [0.3, 0.3, -2.0]]


def _scenario(table: str = "", starts=STARTS, noise: str = "none", more: str = "", controller: str = "wander", **kw):
    rab = f", range_and_bearing = {{ {table} }}" if table else ""
    body = (f'{more}[[group]]\ncount = {len(starts)}\ncontroller = "{controller}"\nstarts = {starts}\n'
            f'robot = {{ model = "epuck", sensors = ["range_and_bearing"]{rab} }}\n')  # fmt: skip
    return arena(body, noise=noise, **kw)


def _rab(table: str = "", **kw) -> list[dict[str, np.ndarray]]:
    return [{k: v for k, v in p.items() if k.startswith("rab_")} for p in ArenaWorld(_scenario(table, **kw)).perceive()]


def _expected(starts, me: int, reach: float = 0.8) -> list[tuple[float, float]]:
    """(distance, bearing from the heading in [-pi, pi)) of every other robot within reach, nearest first."""
    x, y, t = starts[me]
    out = []
    for j, (u, v, _) in enumerate(starts):
        d = math.hypot(u - x, v - y)
        if j != me and d <= reach:
            out.append((d, (math.atan2(v - y, u - x) - t + math.pi) % (2 * math.pi) - math.pi))
    return sorted(out)


def test_hand_placed_robots_read_exact_distances_and_bearings_nearest_first():
    for me, p in enumerate(_rab()):
        expected = _expected(STARTS, me)
        n = len(expected)
        assert p["rab_count"] == n == 3
        np.testing.assert_allclose(p["rab_distance"][:n], [d for d, _ in expected], rtol=0, atol=1e-12)
        np.testing.assert_allclose(p["rab_bearing"][:n], [b for _, b in expected], rtol=0, atol=1e-12)
        assert np.all(np.diff(p["rab_distance"][:n]) > 0) and np.all(p["rab_distance"][n:] == np.inf)
        assert p["rab_distance"].shape == (16,) and p["rab_data"].shape == (16, 4) and p["rab_data"].dtype == np.uint8
    first = _rab()[0]
    assert first["rab_distance"][:3] == pytest.approx([0.1, 0.2, math.hypot(0.2, 0.2)])
    assert first["rab_bearing"][:3] == pytest.approx([0.0, math.pi / 2, -3 * math.pi / 4])


def test_the_range_cuts_and_max_neighbours_caps_with_padding_rows():
    cut = _rab("range = 0.25")
    assert cut[0]["rab_count"] == 2 and cut[0]["rab_distance"][:2] == pytest.approx([0.1, 0.2])
    assert cut[3]["rab_count"] == 0 and np.all(cut[3]["rab_distance"] == np.inf)  # robot 3 is alone
    assert np.all(cut[3]["rab_bearing"] == 0) and np.all(cut[3]["rab_data"] == 0)
    capped = _rab("max_neighbours = 2, payload = 3")
    assert capped[0]["rab_count"] == 2 and capped[0]["rab_distance"] == pytest.approx([0.1, 0.2])
    assert capped[0]["rab_data"].shape == (2, 3)
    assert [p["rab_distance"].shape for p in capped] == [(2,)] * 4


def test_walls_and_robots_between_two_robots_cut_their_link_unless_occlusion_is_off():
    starts = [[0.3, 0.5, 0.0], [0.7, 0.5, 0.0], [0.3, 0.2, 0.0], [0.5, 0.2, 0.0], [0.7, 0.2, 0.0]]
    wall = "[[wall]]\nrect = [0.49, 0.4, 0.51, 0.6]\n"  # between robots 0 and 1
    seen = _rab("range = 0.45", starts=starts, more=wall)
    diagonal = math.hypot(0.2, 0.3)  # robot 0 to robot 3
    assert seen[0]["rab_count"] == 2 and seen[0]["rab_distance"][:2] == pytest.approx([0.3, diagonal])  # not 1
    assert seen[2]["rab_count"] == 2 and seen[2]["rab_distance"][:2] == pytest.approx([0.2, 0.3])  # 3 hides 4
    through = _rab("range = 0.45, occlusion = false", starts=starts, more=wall)
    assert through[0]["rab_count"] == 3 and through[0]["rab_distance"][:3] == pytest.approx([0.3, diagonal, 0.4])
    assert through[2]["rab_count"] == 3 and through[2]["rab_distance"][:3] == pytest.approx([0.2, 0.3, 0.4])


class Talker:
    """Stands still and broadcasts (agent, tick) as two bytes, or what `say` gives; wheels from `wheels`."""

    def __init__(self, agent: int, say=None, wheels=None):
        self.agent, self.tick, self.heard = agent, 0, []
        self.say, self.wheels = say, wheels

    def step(self, perception):
        if "rab_data" in perception:
            self.heard.append((perception["rab_data"].copy(), perception["rab_distance"].copy()))
        self.tick += 1
        return (self.wheels or (lambda t: [0.0, 0.0]))(self.tick - 1)

    def broadcast(self):
        return bytes([self.agent, self.tick - 1]) if self.say is None else self.say(self.tick - 1)


def test_what_a_robot_broadcasts_is_heard_by_its_neighbours_one_tick_later():
    engine = ArenaEngine(_scenario("payload = 2"))
    engine.controllers = [Talker(a) for a in range(4)]
    engine.step(4)
    for tick, (data, distance) in enumerate(engine.controllers[0].heard):
        assert distance[:3] == pytest.approx([0.1, 0.2, math.hypot(0.2, 0.2)])  # robots 1, 2, 3: nobody moved
        want = [[0, 0]] * 3 if tick == 0 else [[1, tick - 1], [2, tick - 1], [3, tick - 1]]
        assert data[:3].tolist() == want, tick
        assert not data[3:].any()


def test_a_refused_actions_broadcast_is_dropped_and_a_payload_is_cut_or_padded():
    engine = ArenaEngine(_scenario("payload = 3"))
    long, short = (lambda t: bytes([9, t, 7, 7, 7])), (lambda t: bytes([t]))
    refused = Talker(1, say=long, wheels=lambda t: [math.nan, 0.0] if t == 2 else [0.0, 0.0])
    engine.controllers = [Talker(0), refused, Talker(2, say=short), Talker(3)]
    engine.step(5)
    heard = [data[:2].tolist() for data, _ in engine.controllers[0].heard]  # robots 1 and 2
    assert heard[1] == [[9, 0, 7], [0, 0, 0]]
    assert heard[3] == [[9, 1, 7], [2, 0, 0]]  # robot 1's tick-2 action was refused: its tick-1 words stay
    assert heard[4] == [[9, 3, 7], [3, 0, 0]]
    assert engine.world.rejected["not finite"] == 1
    talker = Talker(5)
    talker.tick = 1
    assert broadcasts([talker, object()], [5, 6]) == [(5, bytes([5, 0]))]  # a controller without broadcast() is silent


def test_robots_without_the_sensor_are_not_heard_and_payloads_of_two_sizes_meet():
    group = '[[group]]\ncount = 1\ncontroller = "wander"\nstart = {start}\nrobot = {{ model = "epuck"{rab} }}\n'
    body = (group.format(start=[0.5, 0.5, 0.0], rab=', range_and_bearing = { payload = 4 }')
            + group.format(start=[0.6, 0.5, 0.0], rab=', range_and_bearing = { payload = 4 }')
            + group.format(start=[0.5, 0.7, 0.0], rab=', range_and_bearing = { payload = 2 }')
            + group.format(start=[0.3, 0.3, 0.0], rab=""))  # fmt: skip
    engine = ArenaEngine(arena(body))
    engine.controllers = [Talker(a, say=lambda t, a=a: bytes([a, t, 5, 6])) for a in range(4)]
    engine.step(2)
    assert engine.world.rab_sent.tolist() == [[0, 1, 5, 6], [1, 1, 5, 6], [2, 1, 0, 0], [0, 0, 0, 0]]
    _, (data, distance) = engine.controllers[0].heard
    assert int(np.isfinite(distance).sum()) == 2 and distance[:2] == pytest.approx([0.1, 0.2])  # not robot 3
    assert data[:2].tolist() == [[1, 0, 5, 6], [2, 0, 0, 0]]  # robot 2 sends 2 bytes
    data, distance = engine.controllers[2].heard[1]
    assert distance[:2] == pytest.approx([0.2, math.hypot(0.1, 0.2)]) and data[:2].tolist() == [[0, 0], [1, 0]]
    assert engine.controllers[3].heard == []


def test_noise_is_drawn_per_seed_robot_tick_and_neighbour_slot():
    low = _rab(noise="low")
    assert [p["rab_count"] for p in low] == [3] * 4
    for a, b in zip(low, _rab(noise="low"), strict=True):
        for k in a:
            np.testing.assert_array_equal(a[k], b[k])
    exact = _rab()
    assert not np.array_equal(low[0]["rab_distance"], exact[0]["rab_distance"])
    assert np.abs(low[0]["rab_distance"][:3] / exact[0]["rab_distance"][:3] - 1).max() < 0.25  # 5% std
    reseeded = [{k: v for k, v in p.items() if k.startswith("rab_")}
                for p in ArenaWorld(_scenario(noise="low").with_overrides(seed=7)).perceive()]  # fmt: skip
    assert not np.array_equal(low[0]["rab_bearing"], reseeded[0]["rab_bearing"])


def test_a_large_swarm_finds_the_same_neighbours_through_the_kd_tree(monkeypatch):
    rng = np.random.default_rng(3)
    grid = np.stack(np.meshgrid(np.arange(9), np.arange(9)), -1).reshape(-1, 2) * 0.2 + 0.15
    xy, heading = grid + rng.uniform(-0.05, 0.05, grid.shape), rng.uniform(-3, 3, len(grid))
    starts = [[float(x), float(y), float(t)] for (x, y), t in zip(xy, heading, strict=True)]
    scenario = _scenario("range = 0.5, max_neighbours = 6", starts=starts, noise="high", w=2.0, h=2.0)
    dense = ArenaWorld(scenario).perceive()
    monkeypatch.setattr(range_bearing, "DENSE_UP_TO", 0)
    tree = ArenaWorld(scenario).perceive()
    assert sum(int(p["rab_count"]) for p in dense) > 4 * len(starts)
    for a, b in zip(dense, tree, strict=True):
        for k in ("rab_distance", "rab_bearing", "rab_data", "rab_count"):
            np.testing.assert_array_equal(a[k], b[k])


@pytest.mark.parametrize(("table", "where"), [
    ("range = -1", "range_and_bearing.range"),
    ("range = 0", "range_and_bearing.range"),
    ("bearing_noise = -0.1", "range_and_bearing.bearing_noise"),
    ("max_neighbours = 0", "range_and_bearing.max_neighbours"),
    ("payload = 100000", "range_and_bearing.payload"),
    ("occlusion = 1", "range_and_bearing.occlusion"),
    ("ids = true", "range_and_bearing"),
])  # fmt: skip
def test_a_bad_range_and_bearing_table_is_refused_in_one_line(table, where):
    with pytest.raises(ScenarioError) as err:
        _scenario(table)
    assert where in err.value.where and "\n" not in str(err.value), str(err.value)


def test_a_controller_is_told_the_range_the_count_and_the_payload():
    robot = controller_params(_scenario("range = 0.5, payload = 8"), 0)["robot"]
    assert (robot["rab_range"], robot["rab_max_neighbours"], robot["rab_payload"]) == (0.5, 16, 8)
    bare = controller_params(arena('[[group]]\ncount = 1\ncontroller = "wander"\n'), 0)["robot"]
    assert bare["rab_range"] is None and bare["rab_payload"] is None


def test_broadcasts_cross_the_wire_and_a_stray_one_is_refused():
    sent = arena_proto.actions(3, [4, 5], np.zeros((2, 3)), rab=[(4, b"\x01\x02"), (5, b"")])
    got = arena_proto.parse_acts(sent)
    assert isinstance(got, arena_proto.ArenaActs) and got.rab == [(4, b"\x01\x02"), (5, b"")]
    assert arena_proto.parse_acts(arena_proto.actions(3, [4], np.zeros((1, 2)))).rab == []
    stray = arena_proto.parse_acts(arena_proto.actions(3, [4], np.zeros((1, 2)), rab=[(6, b"x")]))
    assert isinstance(stray, arena_proto.Rejected) and "rab" in stray.reason
    huge = arena_proto.parse_acts(arena_proto.actions(3, [4], np.zeros((1, 2)), rab=[(4, bytes(70000))]))
    assert isinstance(huge, arena_proto.Rejected)


def test_a_resumed_world_hears_what_was_broadcast_before_the_save():
    engine = ArenaEngine(_scenario("payload = 2"))
    engine.controllers = [Talker(a) for a in range(4)]
    engine.step(3)
    world = ArenaWorld(engine.world.scenario)
    world.restore(engine.world.snapshot())
    np.testing.assert_array_equal(world.rab_sent, [[a, 2] for a in range(4)])
    assert world.perceive()[0]["rab_data"][:3].tolist() == [[1, 2], [2, 2], [3, 2]]


def test_lockstep_wanderers_broadcasting_equal_in_process_bit_for_bit():
    from tests.distributed import run_world

    starts = [[0.3, 0.3, 0.0], [0.7, 0.3, 1.0], [0.3, 0.7, 2.0], [0.7, 0.7, 3.0]]
    scenario = _scenario("", starts=starts, noise="low", max_ticks=60)
    engine = ArenaEngine(scenario)
    engine.run()
    _, world = run_world(scenario, "arena-rab", [("wander", 2, 2)], deadline=20.0)
    np.testing.assert_array_equal(world.pose, engine.world.pose)
    np.testing.assert_array_equal(world.rab_sent, engine.world.rab_sent)
    assert engine.world.rab_sent.tolist() == [[a, 0, 60, 0] for a in range(4)]  # (agent, ticks) little-endian
