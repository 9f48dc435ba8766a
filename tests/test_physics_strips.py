"""A floor cut into physics strips (`physics_strips`): each strip's space steps
on its own thread, the bits depend on the strips and never on the threads, and
contacts across an edge behave as in one space."""

import hashlib
import math
from dataclasses import replace

import numba
import numpy as np
import pytest

from swarm.bench.arena.measure import LASER_BOT, bench_world
from swarm.core.errors import ScenarioError
from swarm.scenario import parse_arena_text
from tests.arena_helpers import arena, box
from world_server.arena import raycast
from world_server.arena.world import ArenaWorld


def _crowd(strips: int, robots: int = 250, side: float = 10.0) -> ArenaWorld:
    return bench_world(robots, LASER_BOT, obstacles=robots // 10, side=side, strips=strips)


def _drive(world: ArenaWorld, ticks: int) -> None:
    turn = np.linspace(-0.3, 0.3, world.n) * world.max_wheel
    wheels = np.column_stack([0.8 * world.max_wheel - turn, 0.8 * world.max_wheel + turn])
    for _ in range(ticks):
        world.apply(wheels)


def _on_threads(threads: int, world: ArenaWorld, ticks: int) -> ArenaWorld:
    try:
        assert raycast.set_threads(threads) == threads
        _drive(world, ticks)
    finally:
        raycast.set_threads(1)
    return world


def test_one_strip_is_the_one_space_to_the_bit():
    """A crowd in one strip, a lost agent's body pinned among it, through two checkpoints: the digest
    of the physics as one pymunk space for the whole floor computes it (like the ray pass's digests,
    it holds on this platform's maths library)."""
    world = bench_world(200, LASER_BOT, obstacles=20, side=10.0)
    turn = np.linspace(-0.3, 0.3, world.n) * world.max_wheel
    wheels = np.column_stack([0.8 * world.max_wheel - turn, 0.8 * world.max_wheel + turn])
    for tick in range(120):
        if tick == 30:
            world.remove_agent(5)
        world.apply(wheels)
    digest = hashlib.sha256()
    for a in (world.pose, world.bodies.collisions, world.bodies.distance, world.bodies.blocked_seconds):
        digest.update(np.ascontiguousarray(a).tobytes())
    assert (digest.hexdigest()[:32], int(world.bodies.collisions.sum())) == ("4c7467a440153dec8ba3f3b7956ccca7", 2576)


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs two cores")
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


def test_a_robot_crossing_an_edge_changes_owner_and_leaves_a_ghost_behind():
    body = '[[group]]\ncount = 1\ncontroller = "wander"\nstart = [0.45, 0.5, 0.0]\n'
    world = ArenaWorld(replace(arena(body), physics_strips=2))  # the edge at x = 0.5, the halo 0.214 m
    first, second = world.bodies.strips
    assert world.bodies.owner[0] == 0 and first.own_robots.tolist() == [0] and second.robot_of_row.tolist() == [0]
    while world.pose[0, 0] < 0.52:
        world.apply(np.array([[0.1, 0.1]]))
    assert world.bodies.owner[0] == 1 and second.own_robots.tolist() == [0]
    assert first.robot_of_row.tolist() == [0] and first.own_robots.tolist() == []  # now a ghost there
    while world.pose[0, 0] < 0.75:
        world.apply(np.array([[0.1, 0.1]]))
    assert first.robot_of_row.tolist() == []  # out of its halo: gone from its space


def test_a_floor_without_walls_steps_in_one_space_and_in_strips():
    text = 'kind = "arena"\nsize = [1.0, 1.0]\n[[group]]\ncount = 2\ncontroller = "wander"\n'
    text += "starts = [[0.3, 0.5, 0.0], [0.7, 0.5, 3.141592653589793]]\n"
    for strips in (1, 2):
        world = ArenaWorld(replace(parse_arena_text(text, "t.toml"), physics_strips=strips))
        for _ in range(60):
            world.apply(np.array([[0.1, 0.1], [0.1, 0.1]]))
        assert world.bodies.collisions.tolist() == [1, 1] and world.pose[1, 0] - world.pose[0, 0] > 0.07


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


@pytest.mark.parametrize("strips", [0, 65, 5])  # none, over the most, narrower than the halo
def test_a_strip_count_out_of_range_is_refused_in_one_line(strips):
    text = f"physics_strips = {strips}\n" + box('[[group]]\ncount = 1\ncontroller = "wander"\n')
    with pytest.raises(ScenarioError) as error:
        parse_arena_text(text, "t.toml")
    assert "physics_strips" in str(error.value) and "\n" not in str(error.value)
    assert "expected 1 to 4" in str(error.value)  # 1 m / 0.214 m


def test_the_halo_is_two_reaches_of_a_diameter_and_a_period_of_two_robots_at_twice_the_top_speed():
    s = arena('[[group]]\ncount = 1\ncontroller = "wander"\n')
    assert math.isclose(s.physics_halo(), 2 * (2 * 0.037 + 2 * 2 * 0.129 * 0.064))


def test_strips_resume_bit_for_bit_through_entries_a_lost_agent_and_an_obstacle_across_the_edge():
    """As a world server runs them: robots enter while the world runs, one agent is lost (its body
    pinned) by the edge at x = 0.4, and a box across the edge comes at a checkpoint and goes later."""
    body = "[[obstacle]]\nrect = [0.37, 0.3, 0.43, 0.36]\nappear = 50\nvanish = 130\n"
    body += '[[group]]\ncount = 12\ncontroller = "wander"\n'
    crowd = replace(arena(body, w=0.8, h=0.8, max_ticks=100_000), physics_strips=2)

    def push(world: ArenaWorld, ticks: range) -> None:
        for t in ticks:
            if t == 20:
                world.enter(range(6, 12))
            if t == 30:
                world.remove_agent(int(np.argmin(np.abs(world.pose[:6, 0] - 0.4))))
            world.apply(np.random.default_rng(t // 20).uniform(0.02, 0.12, (world.n, 2)))

    a = ArenaWorld(crowd, parked=True)
    a.enter(range(6))
    push(a, range(100))
    b = ArenaWorld(crowd, parked=True)
    b.restore(a.checkpointed)
    push(a, range(100, 200))
    push(b, range(100, 200))
    np.testing.assert_array_equal(a.pose, b.pose)
    np.testing.assert_array_equal(a.bodies.collisions, b.bodies.collisions)
    assert a.bodies.collisions.sum() > 20 and (~a.present).sum() == 1 and a.in_world.all()
