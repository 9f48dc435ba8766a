"""The compiled ray pass against brute force, and sensors against hand calculations."""

import math

import numpy as np
import pytest

from tests.arena_helpers import arena
from world_server.arena.face.sensors.ir import IR_DISTANCE, IR_VALUE
from world_server.arena.raycast import NO_HIT, brute_force
from world_server.arena.world import ArenaWorld


def _random_world(seed: int, robots: int, obstacles: int, cell: float | None = None) -> ArenaWorld:
    rng = np.random.default_rng(seed)
    walls = ""
    for _ in range(obstacles):
        x, y = rng.uniform(0.5, 9.0, 2)
        wx, wy = rng.uniform(0.1, 1.0, 2)
        walls += f"[[wall]]\nrect = [{x}, {y}, {min(x + wx, 9.9)}, {min(y + wy, 9.9)}]\n"
    for _ in range(5):  # diagonal segments too
        a = rng.uniform(0.5, 9.5, 4)
        walls += f"[[wall]]\nsegment = [{a[0]}, {a[1]}, {a[2]}, {a[3]}]\n"
    body = walls + f'[[group]]\ncount = {robots}\ncontroller = "wander"\nrobot = "scout"\nclearance = 0.0\n'
    return ArenaWorld(arena(body, w=10.0, h=10.0), index_cell=cell)


@pytest.mark.parametrize("seed,cell", [(1, None), (2, 0.3), (3, 2.5)])
def test_index_equals_brute_force(seed, cell):
    world = _random_world(seed, robots=40, obstacles=30, cell=cell)
    rng = np.random.default_rng(seed + 100)
    k = 3000
    robot = rng.integers(0, world.n, k)
    bearing = rng.uniform(-math.pi, math.pi, k)
    max_range = rng.uniform(0.5, 12.0, k)
    ranges, what = world.cast(robot, bearing, max_range)
    xy = world.pose[:, :2]
    for i in range(k):
        r = robot[i]
        d, w = brute_force(xy[r, 0], xy[r, 1], world.pose[r, 2] + bearing[i], max_range[i], r, world.segs,
                           world.seg_on, xy, world.radius)  # fmt: skip
        assert ranges[i] == pytest.approx(d, abs=1e-9)
        if w != what[i]:  # two things at the same distance (a rectangle's corner): either may win
            assert d == pytest.approx(ranges[i], abs=1e-9)
    assert (what == NO_HIT).any() and (what >= 0).any() and (what <= -2).any()


def test_rays_never_see_their_own_robot_and_robots_block_each_other():
    body = '[[group]]\ncount = 2\ncontroller = "carrot"\nstarts = [[0.3, 0.5, 0.0], [0.6, 0.5, 3.14159]]\n'
    world = ArenaWorld(arena(body))
    ranges, what = world.cast(np.array([0, 1]), np.array([0.0, 0.0]), np.array([5.0, 5.0]))
    assert what[0] == -2 - 1 and what[1] == -2 - 0
    assert ranges[0] == pytest.approx(0.3 - world.radius[1], abs=1e-6)


def _one(body_extra: str, start: str, robot: str = "epuck", noise: str = "none") -> dict:
    body = body_extra + f'[[group]]\ncount = 1\ncontroller = "wander"\nstart = {start}\n'
    return ArenaWorld(arena(body, robot=robot, noise=noise)).perceive()[0]


@pytest.mark.parametrize(("colour", "factor"), [
    (255, 1.0), (128, 0.2 + 0.8 * 128 / 255), ("[150, 110, 70]", 0.2 + 0.8 * 150 / 255),
])  # fmt: skip
def test_ir_reads_the_response_curve_at_the_hand_computed_distance(colour, factor):
    # A wall face at x = 0.55, the e-puck at x = 0.5 facing it.  Its front sensors sit 31.6 mm from its
    # centre (E-puck.proto), inside the 37 mm rim, and measure from there, as Webots does.  As Webots'
    # infra-red sensors, a surface reflects by 0.2 + 0.8 * its red level: a white wall reads the curve
    # at the true distance, a darker one as if farther.
    p = _one(f"[[wall]]\nrect = [0.55, 0.3, 0.6, 0.7]\ncolour = {colour}\n", "[0.5, 0.5, 0.0]")
    for k, bearing in ((0, -0.30), (7, 0.30)):
        d = 0.05 / math.cos(bearing) - 0.0316
        assert p["ir"][k] == pytest.approx(np.interp(d / factor, IR_DISTANCE, IR_VALUE), rel=1e-9)
    assert p["ir"][1] > 0 and p["ir"][3] == 0.0 and p["ir"][4] == 0.0  # the back sees nothing within 7 cm


def test_ir_measures_from_each_sensor_so_a_touching_wall_reads_the_curve_at_rim_minus_mount():
    # The e-puck's rim touches a white wall ahead: ps0 and ps7 (31.6 mm from the centre) read the curve
    # at 5.4 mm, not at 0 (4095), and a model with its sensors on the rim reads it at 0.
    wall = "[[wall]]\nrect = [0.537, 0.3, 0.6, 0.7]\ncolour = 255\n"
    p = _one(wall, "[0.5, 0.5, 0.0]")
    d = 0.037 / math.cos(0.30) - 0.0316
    assert p["ir"][0] == pytest.approx(np.interp(d, IR_DISTANCE, IR_VALUE), rel=1e-9)
    assert p["ir"][0] < 4095 * 0.6
    on_rim = 'robot = { model = "epuck", ir = { mounts = [0.037, 0.037, 0.037, 0.037, 0.037, 0.037, 0.037, 0.037] } }'
    body = wall + f'[[group]]\ncount = 1\ncontroller = "wander"\nstart = [0.5, 0.5, 0.0]\n{on_rim}\n'
    rim = ArenaWorld(arena(body, noise="none")).perceive()[0]
    assert rim["ir"][0] == pytest.approx(np.interp(0.037 / math.cos(0.30) - 0.037, IR_DISTANCE, IR_VALUE), rel=1e-9)
    assert rim["ir"][0] > p["ir"][0]


def test_camera_sector_sees_the_coloured_wall_ahead_and_its_grey_level():
    p = _one("[[wall]]\nrect = [0.8, 0.2, 0.85, 0.8]\ncolour = [255, 0, 0]\n", "[0.5, 0.5, 0.0]", robot="animat")
    assert list(p["camera_rgb"][0]) == [255, 0, 0]
    assert p["camera_grey"][0] == round(0.299 * 255)
    assert p["camera_range"][0] == pytest.approx(0.3, abs=1e-9)  # the sector's nearest ray is the central one
    behind = p["camera_range"][18]  # sector centred on pi: the west boundary's face at x = 0.02
    assert behind == pytest.approx(0.48, abs=1e-3)
    assert p["sonar"][0] == pytest.approx(0.3, abs=1e-9)  # no noise: the cone's nearest echo


def test_noise_is_keyed_by_seed_agent_and_tick():
    body = '[[group]]\ncount = 2\ncontroller = "wander"\nstarts = [[0.3, 0.3, 0.0], [0.7, 0.7, 0.0]]\n'
    a = ArenaWorld(arena(body, robot="animat", noise="low"))
    b = ArenaWorld(arena(body, robot="animat", noise="low"))
    pa, pb = a.perceive(), b.perceive()
    assert np.array_equal(pa[0]["sonar"], pb[0]["sonar"]) and np.array_equal(pa[1]["compass"], pb[1]["compass"])
    zero = ArenaWorld(arena(body, robot="animat", noise="none")).perceive()
    err = pa[0]["compass"] - zero[0]["compass"]
    assert 0 < abs((err + math.pi) % (2 * math.pi) - math.pi) <= math.radians(10)
    assert np.all(np.abs(pa[0]["sonar"] - zero[0]["sonar"]) <= 0.10 + 0.3)  # range error plus the turned cone


def test_position_noise_has_the_paper_std():
    body = '[[group]]\ncount = 1\ncontroller = "carrot"\nstart = [0.5, 0.5, 0.0]\n'
    world = ArenaWorld(arena(body, noise="high"))
    xs = []
    for _ in range(400):
        xs.append(world.perceive()[0]["position"] - world.pose[0, :2])
        world.apply(np.zeros((1, 2)))
    xs = np.array(xs)
    assert xs.std(axis=0) == pytest.approx([0.02, 0.02], rel=0.15)
    assert np.abs(xs.mean(axis=0)).max() < 0.004


def test_laser_without_noise_measures_geometry():
    world = ArenaWorld(arena('[[group]]\ncount = 1\ncontroller = "wander"\nrobot = "scout"\nstart = [0.5, 0.4, 0.0]\n',
                            noise="none"))  # fmt: skip
    scan = world.perceive()[0]["laser"]
    assert scan[0] == pytest.approx(0.98 - 0.5, abs=1e-9)  # east inner face at x = 0.98
    assert scan[90] == pytest.approx(0.98 - 0.4, abs=1e-9)  # north
    assert scan[180] == pytest.approx(0.5 - 0.02, abs=1e-9)  # west


def test_the_sensing_pass_over_every_core_reads_what_the_serial_pass_reads():
    """`--threads`: the same ranges and hits, bit for bit, for 300 laser robots among 100 boxes, and a run's
    summary the same at any thread count."""
    import json
    import subprocess
    import sys

    from swarm.bench.arena.measure import LASER_BOT, bench_world
    from world_server.arena import raycast

    world = bench_world(300, LASER_BOT)
    robot = np.repeat(np.arange(world.n), 64)
    bearing = np.tile(np.linspace(-math.pi, math.pi, 64, endpoint=False), world.n)
    reach = np.full(len(robot), 5.0)
    try:
        assert raycast.set_threads(1) == 1
        serial = world.cast(robot, bearing, reach)
        assert raycast.set_threads(2) == min(2, raycast.numba.config.NUMBA_NUM_THREADS)
        parallel = world.cast(robot, bearing, reach)
    finally:
        raycast.set_threads(1)
    np.testing.assert_array_equal(serial[0], parallel[0])
    np.testing.assert_array_equal(serial[1], parallel[1])
    runs = [subprocess.run([sys.executable, "-m", "swarm", "run", "zmaze", "--controller", "wander", "--agents", "6",
                            "--max-ticks", "60", "--json", "--threads", n], capture_output=True, text=True, timeout=300)
            for n in ("1", "0")]  # fmt: skip
    summaries = [json.loads(r.stdout.strip().splitlines()[-1]) for r in runs]
    assert [r["pose"] for r in summaries[0]["robots"]] == [r["pose"] for r in summaries[1]["robots"]]
    bad = subprocess.run([sys.executable, "-m", "swarm", "run", "zmaze", "--threads", "-1"], capture_output=True,
                         text=True, timeout=120)  # fmt: skip
    assert bad.returncode == 2 and bad.stderr.strip().splitlines() == [
        "swarm: error: command line: --threads: 0 (every core) or a number of cores"
    ]


@pytest.mark.parametrize(("command", "given", "used"), [("run", None, "every"), ("up", None, 1), ("world", None, 1),
                                                        ("run", 1, 1), ("up", 0, "every")])  # fmt: skip
def test_swarm_run_senses_on_every_core_unless_told_and_a_world_beside_agents_on_one(command, given, used):
    from argparse import Namespace

    from swarm.cli_arena import arena_overrides
    from swarm.scenario import load_scenario
    from world_server.arena import raycast

    args = Namespace(command=command, threads=given, start=None, goal=None, noise=None, max_ticks=None)
    try:
        arena_overrides(load_scenario("zmaze"), args, {"agents": None, "controller": None, "seed": None})
        assert raycast.threads() == (raycast.numba.config.NUMBA_NUM_THREADS if used == "every" else used)
    finally:
        raycast.set_threads(1)


def test_a_pass_too_small_to_pay_for_the_threads_stays_on_one():
    from world_server.arena import raycast

    try:
        raycast.set_threads(2)
        several = raycast.threads() > 1
        assert raycast.parallel(raycast.PARALLEL_RAYS, raycast.PARALLEL_RAYS) is several
        assert not raycast.parallel(raycast.PARALLEL_RAYS - 1, raycast.PARALLEL_RAYS)
    finally:
        raycast.set_threads(1)
