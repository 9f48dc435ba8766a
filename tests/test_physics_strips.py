"""A floor cut into physics strips (`physics_strips`): each strip's space steps
on its own thread, the bits depend on the strips and never on the threads, and
contacts across an edge behave as in one space."""

import math
from dataclasses import replace

import numpy as np
import pytest

from swarm.bench.arena.measure import LASER_BOT, bench_world
from swarm.core.errors import ScenarioError
from swarm.scenario import parse_arena_text
from tests.arena_helpers import arena, box
from world_server.arena import raycast
from world_server.arena.world import ArenaWorld


def _crowd(strips: int, robots: int = 250, side: float = 10.0) -> ArenaWorld:
    world = bench_world(robots, LASER_BOT, obstacles=robots // 10, side=side)
    return ArenaWorld(replace(world.scenario, physics_strips=strips))


def _drive(world: ArenaWorld, ticks: int) -> None:
    turn = np.linspace(-0.3, 0.3, world.n) * world.max_wheel
    wheels = np.column_stack([0.8 * world.max_wheel - turn, 0.8 * world.max_wheel + turn])
    for _ in range(ticks):
        world.apply(wheels)


def _on_threads(threads: int, world: ArenaWorld, ticks: int) -> ArenaWorld:
    try:
        raycast.set_threads(threads)
        _drive(world, ticks)
    finally:
        raycast.set_threads(1)
    return world


def test_strips_give_the_same_bits_on_one_thread_and_on_two():
    one, two = _on_threads(1, _crowd(3), 120), _on_threads(2, _crowd(3), 120)  # through two checkpoints
    np.testing.assert_array_equal(one.pose, two.pose)
    np.testing.assert_array_equal(one.bodies.collisions, two.bodies.collisions)
    np.testing.assert_array_equal(one.bodies.blocked_seconds, two.bodies.blocked_seconds)
    assert one.bodies.collisions.sum() > 100
    crossed = np.floor(one.pose[:, 0] / (10.0 / 3)) != np.floor(one.start_pose[:, 0] / (10.0 / 3))
    assert crossed.sum() > 10  # robots did go from strip to strip


def test_a_crowd_in_strips_collides_and_travels_as_in_one_space():
    """The same crowd in one space and in four strips: the runs part ways (any change to a
    chaotic crowd does that), but contacts across the edges are counted once and shared as
    in one space, so the totals agree and no pair sinks deeper into each other."""
    worlds = {k: _crowd(k) for k in (1, 4)}
    deepest = {}
    for k, world in worlds.items():
        deepest[k] = 0.0
        for _ in range(6):
            _drive(world, 20)
            xy = world.pose[:, :2]
            gap = np.hypot(*(xy[:, None] - xy[None]).transpose(2, 0, 1)) + np.eye(world.n) * 9
            deepest[k] = max(deepest[k], float(2 * LASER_BOT.radius - gap.min()))
    one, four = worlds[1].bodies, worlds[4].bodies
    assert one.collisions.sum() > 300
    assert abs(four.collisions.sum() / one.collisions.sum() - 1) < 0.05
    assert abs(four.distance.sum() / one.distance.sum() - 1) < 0.02
    assert deepest[4] < max(2 * deepest[1], 0.002)


def test_a_lone_robot_crossing_every_strip_drives_exactly_as_in_one_space():
    body = '[[group]]\ncount = 1\ncontroller = "wander"\nstart = [0.1, 0.5, 0.0]\n'
    one, three = (ArenaWorld(replace(arena(body), physics_strips=k)) for k in (1, 3))
    for _ in range(120):
        one.apply(np.array([[0.1, 0.1]]))
        three.apply(np.array([[0.1, 0.1]]))
    assert three.pose[0, 0] > 0.8
    np.testing.assert_array_equal(one.pose, three.pose)


def test_a_robot_sliding_along_a_wall_across_edges_counts_one_contact():
    """Its ghost in the next strip touched the wall too: crossing, the contact goes on."""
    body = '[[group]]\ncount = 1\ncontroller = "wander"\nstart = [0.1, 0.06, -0.2]\n'
    worlds = [ArenaWorld(replace(arena(body), physics_strips=k)) for k in (1, 3)]
    for world in worlds:
        for _ in range(120):
            world.apply(np.array([[0.1, 0.1]]))
    one, three = worlds
    assert three.pose[0, 0] > 0.8 and one.bodies.collisions[0] == three.bodies.collisions[0] == 1
    np.testing.assert_allclose(one.pose, three.pose, atol=1e-9)


def test_robots_meeting_head_on_at_an_edge_do_not_pass_through_each_other():
    body = '[[group]]\ncount = 2\ncontroller = "carrot"\nstarts = [[0.3, 0.5, 0.0], [0.7, 0.5, 3.141592653589793]]\n'
    worlds = [ArenaWorld(replace(arena(body), physics_strips=k)) for k in (1, 2)]  # the edge at x = 0.5
    for world in worlds:
        for _ in range(80):
            world.apply(np.array([[0.1, 0.1], [0.1, 0.1]]))
    one, two = worlds
    assert two.pose[1, 0] - two.pose[0, 0] >= 2 * 0.037 - 0.003
    np.testing.assert_array_equal(one.bodies.collisions, two.bodies.collisions)
    np.testing.assert_allclose(one.pose, two.pose, atol=1e-6)


@pytest.mark.parametrize("strips", [0, 65, 5])
def test_strips_narrower_than_their_halo_are_refused_in_one_line(strips):
    text = f"physics_strips = {strips}\n" + box('[[group]]\ncount = 1\ncontroller = "wander"\n')
    with pytest.raises(ScenarioError) as error:
        parse_arena_text(text, "t.toml")
    assert "physics_strips" in str(error.value) and "\n" not in str(error.value)
    assert "expected 1 to 4" in str(error.value)  # 1 m / 0.214 m


def test_the_halo_is_two_reaches_of_a_diameter_and_a_period_of_two_robots_at_twice_the_top_speed():
    s = arena('[[group]]\ncount = 1\ncontroller = "wander"\n')
    assert math.isclose(s.physics_halo(), 2 * (2 * 0.037 + 2 * 2 * 0.129 * 0.064))
