"""The arena world: bodies, actions, schedules, scenarios, A* and the carrot controller."""

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from agents.controllers.navigation.astar import Planner
from swarm.core.errors import ScenarioError
from swarm.engines.arena import ArenaEngine
from swarm.scenario import load_scenario, parse_scenario_text
from tests.arena_helpers import arena, box
from world_server.arena.world import ArenaWorld

ONE = '[[group]]\ncount = 1\ncontroller = "wander"\nstart = [{x}, {y}, {t}]\n'


def _world(x=0.5, y=0.5, t=0.0, extra="", **kw) -> ArenaWorld:
    return ArenaWorld(arena(extra + ONE.format(x=x, y=y, t=t), **kw))


def test_straight_and_turning_drive_match_the_kinematics():
    w = _world(0.3, 0.5, 0.0)
    for _ in range(10):
        w.apply(np.array([[0.1, 0.1]]))
    # from rest the body lags one substep (chipmunk moves, then accelerates): 10 periods less 16 ms
    assert w.pose[0, 0] == pytest.approx(0.3 + 0.1 * (0.064 * 10 - 0.016), abs=1e-9)
    assert w.pose[0, 1] == pytest.approx(0.5, abs=1e-9)
    assert w.bodies.distance[0] == pytest.approx(0.1 * (0.064 * 10 - 0.016), abs=1e-9)
    w = _world()
    w.apply(np.array([[-0.05, 0.05]]))  # on the spot, counter-clockwise
    assert w.pose[0, 2] == pytest.approx(2 * 0.05 / 0.053 * 0.064, abs=1e-9)
    assert np.hypot(*(w.pose[0, :2] - 0.5)) < 1e-12


def test_the_animat_turns_at_most_10_degrees_per_second():
    w = _world(robot="animat")
    w.apply(np.array([[-0.4, 0.4]]))
    assert w.pose[0, 2] == pytest.approx(math.radians(10) * 0.064, rel=1e-9)


def test_a_robot_driving_into_a_wall_stops_there_and_counts_it():
    w = _world(0.8, 0.5, 0.0)  # the east wall's face is at x = 0.98
    for _ in range(60):
        w.apply(np.array([[0.129, 0.129]]))
    assert 0.98 - 0.037 - 0.003 < w.pose[0, 0] <= 0.98 - 0.037 + 0.001
    assert w.bodies.collisions[0] >= 1 and w.bodies.blocked_seconds[0] > 1.0


def test_two_robots_meeting_head_on_do_not_pass_through_each_other():
    body = '[[group]]\ncount = 2\ncontroller = "carrot"\nstarts = [[0.3, 0.5, 0.0], [0.7, 0.5, 3.141592653589793]]\n'
    w = ArenaWorld(arena(body))
    for _ in range(80):
        w.apply(np.array([[0.1, 0.1], [0.1, 0.1]]))
    assert w.pose[1, 0] - w.pose[0, 0] >= 2 * 0.037 - 0.003
    assert w.bodies.collisions.min() >= 1


def test_collisions_are_the_contacts_chipmunk_begins_in_a_crowd():
    """Contacts begun are read from the space after each step; a `begin` callback, Chipmunk's own
    word for a new contact, counts the same ones, through the checkpoints' rebuilt spaces too."""
    from swarm.bench.arena.measure import LASER_BOT, bench_world

    w = bench_world(200, LASER_BOT, obstacles=20, side=10.0)
    begun = np.zeros(w.n, np.int64)

    def count(arbiter, space, data):
        for shape in arbiter.shapes:
            if hasattr(shape, "robot"):
                begun[shape.robot] += 1

    turn = np.linspace(-0.4, 0.4, w.n) * w.max_wheel
    wheels = np.column_stack([0.8 * w.max_wheel - turn, 0.8 * w.max_wheel + turn])
    for tick in range(2 * w.scenario.checkpoint + 10):
        if tick % w.scenario.checkpoint == 0:  # a checkpoint rebuilds the space: hook the new one
            w.bodies.space.on_collision(begin=count)
        w.apply(wheels)
    assert begun.sum() > 200
    np.testing.assert_array_equal(w.bodies.collisions, begun)


def test_bad_actions_are_counted_and_never_acted_on():
    w = _world()
    before = w.pose.copy()
    w.apply(np.array([[math.nan, 0.1]]))
    w.apply(np.array([[10.0, 10.0]]))  # far over the e-puck's 12.9 cm/s
    w.apply(np.array([[0.1, 0.1, 0.1, 0.1]]))
    w.apply(np.array([[0.1, 0.1, 1.0]]))  # a consummatory act where there is no metabolism
    w.apply(np.array([[math.inf, -math.inf]]))
    assert np.array_equal(w.pose, before)
    assert w.rejected == {"not finite": 2, "over the wheel limit": 1, "wrong shape": 1, "unknown act": 1}
    assert w.tick == 5


def test_the_compiled_wheel_checks_and_limits_are_numpys_to_the_bit():
    from world_server.arena.wheels import limited, refusals

    rng = np.random.default_rng(8)
    for width in (2, 3):
        actions = rng.normal(0, 0.2, (400, width))
        actions[rng.random((400, width)) < 0.05] = rng.choice([math.nan, math.inf, -math.inf])
        if width == 3:
            actions[:, 2] = rng.choice([0.0, 1.0, 2.0, 3.0, -1.0, 0.5, -0.0, 1e300], 400)
        robots = rng.integers(0, 4, 400)
        max_wheel = np.array([0.1, 0.2, 0.13, 0.3])
        for with_acts in (True, False):
            finite = np.isfinite(actions).all(axis=1)  # the numpy expressions the kernel replaced
            wheels = np.where(finite[:, None], actions[:, :2], 0.0)
            over = (np.abs(wheels) > max_wheel[robots, None] * (1 + 1e-9)).any(axis=1)
            want = np.where(~finite, 0, np.where(over, 1, -1))
            if width == 3:
                act = np.where(finite, actions[:, -1], 0.0)
                known = (act == np.round(act)) & (act >= 0) & (act < 3)
                if not with_acts:
                    known &= act == 0
                want = np.where((want < 0) & ~known, 3, want)
            got = np.empty(400, np.int64)
            refusals(actions, max_wheel, robots, 3, with_acts, got)
            assert np.array_equal(got, want)
    wheels, axle = rng.normal(0, 0.3, (400, 2)), rng.uniform(0.05, 0.3, 400)
    top, turn = rng.uniform(0.05, 0.3, 400), rng.uniform(0.1, 3.0, 400)
    v, w = (wheels[:, 0] + wheels[:, 1]) / 2, (wheels[:, 1] - wheels[:, 0]) / axle
    v = v * np.where(np.abs(v) > top, top / np.maximum(np.abs(v), 1e-12), 1.0)
    w = w * np.where(np.abs(w) > turn, turn / np.maximum(np.abs(w), 1e-12), 1.0)
    got = np.empty((400, 2))
    limited(wheels, axle, top, turn, got)
    assert np.array_equal(got, np.column_stack([v - w * axle / 2, v + w * axle / 2]))


def test_a_scheduled_obstacle_blocks_only_while_present():
    extra = "[[obstacle]]\nrect = [0.6, 0.3, 0.7, 0.7]\nappear = 2\nvanish = 4\n"
    w = _world(0.4, 0.5, 0.0, extra=extra)
    seen = []
    for _ in range(6):
        seen.append(w.cast(np.array([0]), np.array([0.0]), np.array([5.0]))[0][0])
        w.apply(np.zeros((1, 2)))
    assert seen == pytest.approx([0.58, 0.58, 0.2, 0.2, 0.58, 0.58], abs=1e-9)


def test_zones_are_sensed():
    w = _world(0.5, 0.5, extra='[[zone]]\nkind = "dangerous"\ndisc = [0.5, 0.5, 0.1]\n', robot="animat")
    assert w.perceive()[0]["zones"] == 1 << 3


@pytest.mark.parametrize("body,where", [
    ("[[wall]]\nrect = [0.5, 0.5, 0.4, 0.6]\n" + ONE.format(x=0.2, y=0.2, t=0), "wall 5.rect"),
    ("[[wall]]\nrect = [0.5, 0.5, 1.5, 0.6]\n" + ONE.format(x=0.2, y=0.2, t=0), "wall 5"),
    ("[[wall]]\nrect = [0.4, 0.4, 0.6, 0.6]\n" + ONE.format(x=0.5, y=0.5, t=0), "group 1.starts[1]"),
    ('[[group]]\ncount = 1\ncontroller = "dft9"\n', "group 1.controller"),
    ('[[group]]\ncount = 1\nrobot = "tank"\n', "group 1.robot"),
    ('[[group]]\ncount = 2\nstarts = [[0.5, 0.5]]\n', "group 1.starts"),
    ('[[group]]\ncount = 1\nroute = "tour"\n', "group 1.route"),
    ('[[group]]\ncount = 1\ncontroller = "carrot"\nrobot = "animat"\n', "group 1.robot"),
    ('[[group]]\ncount = 1\nspeed = 3\n', "speed"),
    ('[[zone]]\nkind = "lava"\ndisc = [0.5, 0.5, 0.1]\n[[group]]\n', "zone 1.kind"),
    ("[[obstacle]]\nrect = [0.3, 0.3, 0.4, 0.4]\nappear = 5\nvanish = 5\n[[group]]\n", "obstacle 1"),
    ('[[group]]\ncount = 1\nrobot = { model = "epuck", ir = { mounts = [0.03] } }\n', "group 1.robot.ir.mounts"),
    ('[[group]]\ncount = 1\nrobot = { model = "epuck", ir = { mounts = [0.05, 0.03, 0.03, 0.03, 0.03, 0.03, 0.03, '
     '0.03] } }\n', "group 1.robot.ir.mounts"),
])  # fmt: skip
def test_broken_arena_scenarios_name_the_field(body, where):
    with pytest.raises(ScenarioError) as err:
        parse_scenario_text(box(body), "bad.toml")
    assert err.value.source == "bad.toml" and where in err.value.where


def test_drawn_starts_follow_the_seed_and_keep_their_clearance():
    text = box(
        "[[wall]]\nrect = [0.3, 0.3, 0.7, 0.7]\n" + '[[group]]\ncount = 6\ncontroller = "carrot"\nclearance = 0.05\n'
    )
    a = parse_scenario_text(text, "t.toml").start_poses()
    assert np.array_equal(a, parse_scenario_text(text, "t.toml").start_poses())
    assert not np.array_equal(a, parse_scenario_text(text.replace("kind", "seed = 9\nkind"), "t.toml").start_poses())
    from world_server.arena.scenario import clearance_at

    s = parse_scenario_text(text, "t.toml")
    assert (clearance_at(a[:, :2], s.wall_rects(), s.wall_segments()) >= 0.037 + 0.05).all()
    gaps = np.hypot(*(a[:, None, :2] - a[None, :, :2]).transpose(2, 0, 1)) + np.eye(6)
    assert gaps.min() >= 2 * 0.037


def test_astar_finds_the_straight_line_and_respects_clearance():
    empty = Planner((1.0, 1.0), np.zeros((0, 4)), np.zeros((0, 4)), 0.01, 0.04)
    length, path = empty.plan((0.1, 0.5), (0.9, 0.5))
    assert length == pytest.approx(0.8, abs=1e-9) and len(path) == 81
    # a 6 cm gap is narrower than twice the 4 cm clearance: no way through
    wall = np.array([[0.45, 0.0, 0.55, 0.47], [0.45, 0.53, 0.55, 1.0]])
    blocked = Planner((1.0, 1.0), wall, np.zeros((0, 4)), 0.01, 0.04)
    assert blocked.plan((0.1, 0.5), (0.9, 0.5))[0] == math.inf
    wide = np.array([[0.45, 0.0, 0.55, 0.40], [0.45, 0.60, 0.55, 1.0]])
    length, path = Planner((1.0, 1.0), wide, np.zeros((0, 4)), 0.01, 0.04).plan((0.1, 0.9), (0.9, 0.9))
    assert math.isfinite(length) and length > 0.8
    from world_server.arena.scenario import clearance_at

    # clearance is counted between cell centres, as in the original code: within half a cell of 4 cm
    assert clearance_at(path, wide, np.zeros((0, 4))).min() >= 0.04 - 0.005


def test_carrot_reaches_zmaze_goals_close_to_the_optimum():
    s = load_scenario("zmaze")
    for start, goal in (((0.395, 0.205, 0.0), (0.695, 0.705)), ((0.695, 0.405, 0.0), (0.195, 0.805))):
        summary = ArenaEngine(s.with_overrides(start=start, goal=goal, noise="none")).run()
        robot = summary["robots"][0]
        assert summary["finished"] and robot["reached"] and robot["collisions"] == 0
        assert 0.9 < robot["path_ratio"] < 1.15


def _folded_path() -> np.ndarray:
    """Out east along y = 0, up 1.2 cm, back west along y = 0.012: a fold whose legs pass 1.2 cm apart."""
    out = [(0.01 * k, 0.0) for k in range(21)]
    back = [(0.01 * k, 0.012) for k in range(20, -1, -1)]
    return np.array(out + back)


def test_the_papers_carrot_is_the_nearest_point_of_the_whole_path():
    from agents.controllers.navigation.follow import CarrotFollower, PaperCarrotFollower

    path = _folded_path()
    # at x = 5 cm on the way out, facing north: p_look (5, 1) cm is 2 mm from the way back, 1 cm from the way out
    ours = CarrotFollower(path, 3.0, 0.01, 0.05, 40).carrot(0.05, 0.0, math.pi / 2)
    papers = PaperCarrotFollower(path, 3.0, 0.01, 0.05, 40).carrot(0.05, 0.0, math.pi / 2)
    np.testing.assert_allclose(ours, (0.05, 0.0))  # the window keeps to the way out
    np.testing.assert_allclose(papers, (0.05, 0.012))  # eq. 18 jumps across the fold


def test_the_papers_carrot_drives_forward_while_it_turns():
    from agents.controllers.navigation.follow import CarrotFollower, PaperCarrotFollower

    path = np.array([(0.5 - 0.01 * k, 0.5) for k in range(30)])  # the path runs west, behind the robot facing east
    axle, top = 0.053, 0.129
    left, right = PaperCarrotFollower(path, 3.0, 0.01, 0.05, 40).wheels(0.52, 0.5, 0.0, axle, top)
    assert (left + right) / 2 == pytest.approx(0.05)  # cruise speed while it steers
    assert abs(right - left) > 0.1 and max(abs(left), abs(right)) <= top + 1e-12  # a turn as hard as the wheels allow
    left, right = CarrotFollower(path, 3.0, 0.01, 0.05, 40).wheels(0.52, 0.5, 0.0, axle, top)
    assert (left + right) / 2 == pytest.approx(0.0, abs=1e-9) and abs(right - left) > 0.1  # ours turns on the spot


def test_a_bad_carrot_variant_is_refused_in_one_line():
    from agents.controllers.carrot.controller import CarrotParams

    assert CarrotParams.from_table({"variant": "paper"}).variant == "paper"
    assert CarrotParams.from_table(None).variant == "ours"
    with pytest.raises(ValueError, match=r"^\[carrot\]: variant is 'ours' or 'paper', not 'barton'$"):
        CarrotParams.from_table({"variant": "barton"})


def test_arena_runs_are_deterministic_bit_for_bit():
    s = load_scenario("large-maze").with_overrides(noise="high")
    a, b = ArenaEngine(s), ArenaEngine(s)
    a.step(300)
    b.step(300)
    assert np.array_equal(a.world.pose, b.world.pose)


def test_several_robots_share_a_maze():
    text = load_scenario("large-maze")
    s = text.with_overrides(agents=4, seed=5)  # drawn starts, a drawn goal each
    e = ArenaEngine(s)
    e.step(1500)
    assert e.world.bodies.distance.min() > 0.3
    assert int(e.world.finished.sum()) >= 1


def _swarm(*args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "swarm.cli", *args], capture_output=True, text=True, timeout=300)


def test_cli_runs_and_senses_an_arena():
    out = _swarm("run", "zmaze", "--noise", "none", "--json")
    assert out.returncode == 0, out.stderr
    summary = json.loads(out.stdout)
    assert summary["kind"] == "arena" and summary["robots"][0]["reached"]
    sense = _swarm("sense", "zmaze", "--pose", "0.2,0.5,0", "--json")
    assert sense.returncode == 0, sense.stderr
    reading = json.loads(sense.stdout)
    assert reading["position"] and len(reading["ir"]) == 8
    bad = _swarm("run", "zmaze", "--agents", "2", "--start", "0.2,0.2")
    assert bad.returncode == 2 and "one-robot" in bad.stderr and "Traceback" not in bad.stderr


def test_carrot_experiment_writes_its_table(tmp_path):
    from swarm.experiments.billing2015.carrot import run_carrot_experiment

    result = run_carrot_experiment("carrot", "zmaze", 3, 2, 0, tmp_path, progress=False)
    assert result["runs"] == 18  # 3 pairs x ours and the paper's x none / low / high
    assert {"runs.csv", "summary.csv", "table.md", "plot.png"} <= {p.name for p in tmp_path.iterdir()}
    table = (tmp_path / "table.md").read_text()
    assert "FTC-HN" in table and "FTCp-HN" in table and "paper F = 0.97" in table
    conditions = [r["condition"] for r in result["summary"]]
    assert conditions == ["FTC-NN", "FTC-LN", "FTC-HN", "FTCp-NN", "FTCp-LN", "FTCp-HN"]
    assert [r["reached"] for r in result["summary"]][:3] == [3, 3, 3]
    runs = (tmp_path / "runs.csv").read_text()
    assert runs.count(",carrot,paper,") == 9 and runs.count(",carrot,ours,") == 9  # the same pairs, paired


def test_large_maze_pairs_follow_the_seed_and_keep_40_mm_from_walls():
    from swarm.experiments.billing2015.carrot import random_pairs
    from world_server.arena.scenario import clearance_at

    a, b = random_pairs("large-maze", 5, 7), random_pairs("large-maze", 5, 7)
    assert a == b and a != random_pairs("large-maze", 5, 8)
    s = load_scenario("large-maze")
    pts = np.array([p[1:] for p in a]).reshape(-1, 2)
    assert clearance_at(pts, s.wall_rects(), s.wall_segments()).min() >= 0.04


def test_an_arena_recording_reads_back_to_the_printed_summary(tmp_path):
    rrd = tmp_path / "arena.rrd"
    ran = _swarm("run", "large-maze", "--agents", "3", "--seed", "2", "--max-ticks", "600", "--record", str(rrd),
                 "--json")  # fmt: skip
    assert ran.returncode in (0, 1), ran.stderr[-2000:]
    printed = json.loads(ran.stdout)
    rep = _swarm("report", str(rrd), "--out", str(tmp_path / "plots"), "--json")
    assert rep.returncode == 0, rep.stderr[-2000:]
    read = json.loads(rep.stdout)
    for key in ("scenario", "kind", "agents", "seed", "noise", "ticks", "finished", "reached", "with_goal",
                "sim_seconds", "mean_path_ratio", "collisions", "rejected_actions"):  # fmt: skip
        assert read[key] == printed[key], key
    keys = ("agent", "controller", "start", "goal", "reached", "ticks_to_goal", "path_length", "optimal_length",
            "path_ratio", "collisions")  # fmt: skip
    assert [{k: r[k] for k in keys} for r in read["robots"]] == [{k: r[k] for k in keys} for r in printed["robots"]]
    for name in ("trajectories.png", "goals.png", "path_lengths.png"):
        assert (tmp_path / "plots" / name).stat().st_size > 5000


def test_the_arena_recording_holds_walls_robots_headings_and_the_plan(tmp_path):
    from rerun.chunk import RrdReader

    from swarm.recording.arena import ArenaRecorder

    s = load_scenario("zmaze").with_overrides(max_ticks=50)
    engine = ArenaEngine(s)
    rec = ArenaRecorder(tmp_path / "z.rrd", engine.world, engine.goals, {"run_id": "z", "runtime": "in-process"},
                        controllers=engine.controllers)  # fmt: skip
    engine.run(recorder=rec)
    rec.close(engine.summary())
    entities = {c.entity_path.lstrip("/") for c in RrdReader(tmp_path / "z.rrd").stream()}
    for e in ("world/walls", "world/zones", "world/goals", "world/robots", "world/headings", "world/trajectories",
              "world/plans/0", "metrics/reached", "metrics/robots/path_length", "run/meta", "run/summary"):  # fmt: skip
        assert e in entities, e


def test_more_robots_than_goals_get_a_drawn_goal_each():
    from world_server.arena.scenario import clearance_at

    s = load_scenario("zmaze").with_overrides(agents=5, seed=3)
    goals = np.array(s.goals())
    assert np.array_equal(goals, np.array(load_scenario("zmaze").with_overrides(agents=5, seed=3).goals()))
    gaps = np.hypot(*(goals[:, None] - goals[None]).transpose(2, 0, 1)) + np.eye(5)
    assert gaps.min() >= 2 * s.goal_radius
    assert clearance_at(goals, s.wall_rects(), s.wall_segments()).min() >= 0.037 + 0.04
    assert ArenaEngine(s).run()["reached"] >= 4


def test_wall_distance_is_scipys_transform_up_to_the_clearance():
    from scipy.ndimage import distance_transform_edt

    from agents.controllers.navigation.astar import occupancy, wall_distance

    s = load_scenario("large-maze")
    occ = occupancy(s.size, 0.01, s.wall_rects(), s.wall_segments())
    occ[50:53, 100:140] = True  # and a bar away from the walls
    ref = distance_transform_edt(np.pad(~occ, 1, constant_values=False))[1:-1, 1:-1]
    ref[ref > 5.0] = np.inf
    np.testing.assert_array_equal(wall_distance(occ, 5.0), ref)


AOT_CHILD = """
import pickle, sys
from swarm.core import kernels
assert kernels.use_ahead_of_time()
from agents.controllers.arena import as_action, make_controller
name, seed, params, readings = pickle.loads(open(sys.argv[1], "rb").read())
brain = make_controller(name)
brain.reset(seed, 0, params)
actions = [as_action(brain.step(r)).tolist() for r in readings]
pickle.dump((actions, "numba" in sys.modules, "scipy" in sys.modules), open(sys.argv[1] + ".out", "wb"))
"""


def test_the_agents_compiled_astar_equals_the_jit():
    from agents.controllers import aot
    from agents.controllers.navigation.astar import astar_cells
    from swarm.core import kernels

    aot.build()  # once per source version (swarm up builds it too)
    compiled = kernels.load("astar")
    free = np.random.default_rng(3).random((60, 80)) > 0.3
    for si, sj, gi, gj in ((0, 0, 79, 59), (5, 40, 70, 2), (10, 10, 10, 10)):
        free[sj, si] = free[gj, gi] = True
        (c1, p1), (c2, p2) = compiled(free, si, sj, gi, gj), astar_cells(free, si, sj, gi, gj)
        assert c1 == c2 and np.array_equal(p1, p2)


@pytest.mark.parametrize(("controller", "ref"), [
    ("carrot", "zmaze"), ("wander", "zmaze"), ("bg", "bg-exp1"), ("fingerprint", "office"), ("dft", "zmaze"),
])  # fmt: skip
def test_an_agent_process_steps_its_controller_without_numba_exactly_as_in_process(controller, ref, tmp_path):
    """The agents' ahead-of-time kernels (swarm.core.kernels) give the JIT's actions, tick for tick, in a process
    without numba or scipy (each costs an agent process tens of MB: docs/distributed.md)."""
    import pickle
    import subprocess
    import sys

    from agents.controllers import aot
    from agents.controllers.arena import as_action
    from swarm.engines.arena import ArenaEngine
    from world_server.arena.scenario import controller_params

    aot.build()
    s = load_scenario(ref).with_overrides(controller=controller, agents=1, max_ticks=1000)
    engine = ArenaEngine(s)
    brain, readings, actions = engine.controllers[0], [], []

    def step(reading, inner=brain.step):
        readings.append(reading)
        actions.append(as_action(out := inner(reading)).tolist())
        return out

    brain.step = step
    engine.step(40)
    given = tmp_path / "given.pkl"
    given.write_bytes(pickle.dumps((controller, s.seed, controller_params(s, 0), readings)))
    out = subprocess.run([sys.executable, "-c", AOT_CHILD, str(given)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    got, numba_loaded, scipy_loaded = pickle.loads((tmp_path / "given.pkl.out").read_bytes())
    assert got == actions and not numba_loaded
    assert not scipy_loaded  # bg's routes and dft's transforms are compiled or loaded without the package


@pytest.mark.parametrize(("controller", "ref", "has_route"), [
    ("carrot", "zmaze", True), ("fingerprint", "office", True), ("wander", "zmaze", False), ("dft", "zmaze", False),
])  # fmt: skip
def test_route_is_the_path_record_shows_and_costs_no_record(controller, ref, has_route):
    """An agent process asks every robot for its route every tick (to send a new plan to the recording):
    route() gives record()'s path without building the rest of the record (a DFT robot's fields, a map)."""
    engine = ArenaEngine(load_scenario(ref).with_overrides(controller=controller, agents=1, max_ticks=100))
    engine.step(30)
    brain = engine.controllers[0]
    route = getattr(brain, "route", None)
    path = None if route is None else route()
    if has_route:
        assert path is not None and len(path) >= 2
        np.testing.assert_array_equal(path, brain.record()["path"])
    else:
        assert path is None and "path" not in brain.record()


def test_odometry_and_compass_biases_are_drawn_once_per_robot_and_run_and_add_up():
    """A bias (`[robot.odometry] bias`, `[robot.compass] bias`) stays the same every tick of a run and
    differs between robots and seeds, so the odometric path drifts; the fresh per-tick error averages out.
    Without a bias the readings are as they were."""
    from types import SimpleNamespace

    from world_server.arena.face.robots import ANIMAT
    from world_server.arena.face.sensors.compass import Compass
    from world_server.arena.face.sensors.odometry import Odometry
    from world_server.arena.sensors import Noise, Suite

    def mean_readings(model, seed: int, ticks: int = 400) -> tuple[np.ndarray, np.ndarray]:
        suite = Suite(model, np.arange(3), Noise(), seed)
        state = SimpleNamespace(motion=np.tile([0.1, 0.02], (3, 1)), pose=np.zeros((3, 3)))
        odo = np.mean([Odometry.read(model.sensors.odometry, suite.reading(t, state))["odometry"]
                       for t in range(ticks)], axis=0)  # fmt: skip
        heading = np.mean(
            [
                (Compass.read(model.sensors.compass, suite.reading(t, state))["compass"] + np.pi) % (2 * np.pi) - np.pi
                for t in range(ticks)
            ],
            axis=0,
        )  # fmt: skip (true heading 0)
        return odo / [0.1, 0.02] - 1.0, heading

    plain_odo, plain_heading = mean_readings(ANIMAT, 1)
    assert np.abs(plain_odo).max() < 0.01 and np.abs(plain_heading).max() < 0.02  # errors within 5% and 10 deg
    biased = ANIMAT.with_sensors(odometry=Odometry(bias=0.05), compass=Compass(bias=0.1))
    odo, heading = mean_readings(biased, 1)
    assert np.abs(odo).max() > 0.01 and np.abs(odo).max() <= 0.05 + 0.01  # a constant scale error per robot
    assert np.abs(heading).max() > 0.02 and np.abs(heading).max() <= 0.1 + 0.02
    assert len({round(float(x), 6) for x in odo[:, 0]}) == 3  # each robot its own bias
    other, _ = mean_readings(biased, 2)
    assert not np.allclose(other, odo)  # ... and each seed
