"""The bundled arenas hold what their files and docs/arena.md say, and resources behave as the BG paper's."""

import itertools
import math

import numpy as np
import pytest

from swarm.engines.arena import ArenaEngine
from swarm.scenario import bundled_scenarios, load_scenario
from tests.arena_helpers import arena
from world_server import kind_of
from world_server.arena.face.sensors.zones import ZONE_KINDS
from world_server.arena.world import ArenaWorld

ARENAS = [
    "zmaze",
    "large-maze",
    "bg-exp1",
    "bg-exp2",
    "bg-exp3",
    "tmaze-1",
    "tmaze-1.5",
    "tmaze-2",
    "office",
    "office-l",
    "bg-colony",
]


def test_every_bundled_arena_loads_and_ticks():
    assert set(ARENAS) <= set(bundled_scenarios())
    for name in ARENAS:
        s = load_scenario(name)
        assert kind_of(s).name == "arena", name
        e = ArenaEngine(s.with_overrides(max_ticks=3))
        assert e.step(3) == 3, name


def _sees(world: ArenaWorld, grey_level: int) -> bool:
    """Does robot 0's camera see any pixel of this grey level?"""
    return bool((world.perceive()[0]["camera_grey"] == grey_level).any())


def _animat_at(name: str, x: float, y: float, theta: float = 0.0) -> ArenaWorld:
    from dataclasses import replace

    s = load_scenario(name)
    g = replace(s.groups[0], starts=((x, y, theta),))
    return ArenaWorld(replace(s, groups=(g,)))


def test_bg_exp1_resources_cannot_be_seen_from_each_others_vicinity():
    for x, y in ((1.2, 2.2), (2.0, 1.4), (1.9, 2.1), (2.6, 1.0)):  # within about 1 m of Ep: E (white) is hidden
        assert not _sees(_animat_at("bg-exp1", x, y), 255), (x, y)
    for x, y in ((1.2, 6.6), (2.0, 7.6), (2.2, 6.8)):  # within about 1 m of E: Ep (127) is hidden
        assert not _sees(_animat_at("bg-exp1", x, y), 127), (x, y)
    assert _sees(_animat_at("bg-exp1", 1.2, 2.2), 127)  # but each is seen from its own vicinity
    assert _sees(_animat_at("bg-exp1", 1.2, 6.6, math.pi / 2), 255)


def test_bg_exp1_ep_is_in_the_open_of_the_south_room():
    """No niche (the paper says only that neither resource is seen from the other's vicinity): Ep is seen from
    the south room's middle and its north-west corner, where a wall round it would hide it."""
    for x, y in ((4.0, 1.4), (1.2, 3.2), (3.5, 3.2), (2.6, 3.8)):
        assert _sees(_animat_at("bg-exp1", x, y, -math.pi / 2), 127), (x, y)


def test_bg_exp2_blocks_are_told_apart_by_their_greys():
    """Four blocks of one shape round a cross of corridors: only their greys tell the crossings apart."""
    s = load_scenario("bg-exp2")
    greys = [w.colour[0] for w in s.walls if w.name.startswith("block_")]
    assert len(greys) == 4 and len(set(greys)) == 4
    assert not set(greys) & {31, 127, 255, 180}  # neither a resource's grey nor the walls'
    assert min(abs(a - b) for a, b in itertools.combinations(greys, 2)) >= 35  # a unit of grey_scale apart


def test_resources_are_usable_within_70_cm_while_present():
    s = load_scenario("bg-exp2")
    ep2 = next(o for o in s.obstacles if o.name == "Ep2")
    bit = 1 << ZONE_KINDS.index("ingesting")
    near = _animat_at("bg-exp2", ep2.centre[0] + 0.6, ep2.centre[1])
    far = _animat_at("bg-exp2", ep2.centre[0] + 0.8, ep2.centre[1])
    assert near.zones[0] & bit and not far.zones[0] & bit


def test_a_dangerous_area_is_seen_by_the_camera_not_by_sonar_and_can_be_crossed():
    body = ('[[resource]]\nkind = "dangerous"\ncentre = [0.6, 0.5]\n'
            '[[group]]\ncount = 1\ncontroller = "wander"\nrobot = "animat"\nstart = [0.2, 0.5, 0.0]\n')  # fmt: skip
    w = ArenaWorld(arena(body, w=1.5, h=1.0, robot="animat"))
    p = w.perceive()[0]
    assert p["camera_grey"][0] == 31 and p["camera_range"][0] == pytest.approx(0.35 - 0.2, abs=1e-9)
    assert p["sonar"][0] == pytest.approx(1.48 - 0.2, abs=1e-9)  # the east wall, through the mark
    assert p["zones"] & (1 << ZONE_KINDS.index("dangerous"))
    for _ in range(40):
        w.apply(np.array([[0.4, 0.4]]))
    assert w.pose[0, 0] > 0.9  # drove across it


def test_tmaze_right_branch_is_ratio_times_the_left():
    for ratio in (1, 1.5, 2):
        s = load_scenario(f"tmaze-{ratio:g}")
        rects = {w.name: w.coords for w in s.walls}
        stem_x0, stem_x1 = rects["below_left"][2], rects["below_right"][0]
        left = stem_x0 - 0.1
        right = (s.size[0] - 0.1) - stem_x1
        assert right / left == pytest.approx(ratio)
        names = {o.name: o for o in s.obstacles}
        assert names["Ep1"].centre[0] < stem_x0 < stem_x1 < names["Ep2"].centre[0] < names["E"].centre[0]


def test_bg_exp3_the_direct_way_to_the_nearer_ep_passes_the_danger():
    s = load_scenario("bg-exp3")
    names = {o.name: o for o in s.obstacles}
    start = np.array(s.groups[0].starts[0][:2])
    da, ep1 = np.array(names["DA"].centre), np.array(names["Ep1"].centre)
    mouth = np.array([3.8, 1.5])  # the south corridor's 1.2 m mouth
    assert math.dist(start, mouth) + math.dist(mouth, ep1) < math.dist(start, names["Ep2"].centre) + 2.0
    t = np.linspace(0, 1, 50)[:, None]
    way = mouth + t * (ep1 - mouth)
    assert np.hypot(*(way - da).T).min() < 0.7


def test_office_tours_have_the_documented_lengths_and_the_mapping_tour_is_driven():
    s = load_scenario("office")
    lengths = {k: sum(math.dist(a, b) for a, b in itertools.pairwise(r)) for k, r in s.routes.items()}
    assert lengths["mapping"] == pytest.approx(75, rel=0.05)
    assert lengths["localize"] == pytest.approx(250, rel=0.05)
    assert lengths["localize-off-map"] == pytest.approx(250, rel=0.05)
    assert lengths["new-path"] == pytest.approx(250, rel=0.05)
    summary = ArenaEngine(s).run()
    robot = summary["robots"][0]
    assert summary["finished"] and robot["collisions"] == 0 and robot["path_ratio"] < 1.1


def test_the_held_out_office_l_floor_has_its_tours_and_drives_its_mapping_tour():
    s = load_scenario("office-l")
    lengths = {k: sum(math.dist(a, b) for a, b in itertools.pairwise(r)) for k, r in s.routes.items()}
    assert lengths["mapping"] == pytest.approx(75, rel=0.05)
    assert lengths["new-path"] == pytest.approx(250, rel=0.05) and lengths["localize"] == pytest.approx(250, rel=0.05)
    assert len([z for z in s.zones if z.kind == "place"]) == 25
    summary = ArenaEngine(s).run()
    robot = summary["robots"][0]
    assert summary["finished"] and robot["collisions"] == 0 and robot["path_ratio"] < 1.1
