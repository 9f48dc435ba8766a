"""The dft controller (Billing et al. 2015): the field engine against direct
convolution, the field dynamics the paper relies on (one peak over the
stronger bump, self-stabilised but not self-sustained peaks, back-chaining
along a shortest route, release and execution, replanning around an
obstacle), and the robot in the Z-maze, in process and over zenoh."""

from __future__ import annotations

import collections
import json

import numpy as np
import pytest

from agents.controllers.dft.architecture import EBS, TRAVEL, spa_architecture
from agents.controllers.dft.controller import DftController
from agents.controllers.dft.fields import (
    Architecture,
    Coupling,
    Engine,
    Field,
    Input,
    Lateral,
    fill_noise,
    gauss_1d,
    kernel_image,
)
from agents.controllers.dft.params import DftParams, Interface
from agents.controllers.dft.robot import gaussian_2d, heading_images, ir_image, wheel_profiles, wheel_speeds
from swarm.core.errors import ScenarioError
from swarm.engines.arena import ArenaEngine
from swarm.scenario import load_scenario, parse_scenario_text
from tests.arena_helpers import arena, box, rrd_rows

# ------------------------------------------------------------------ engine


def test_gaussian_kernels_are_normalised_and_truncated_at_five_sigma():
    g = gauss_1d(100, 2.0)
    assert g.sum() == pytest.approx(1.0)
    assert np.count_nonzero(g) == 21  # +-ceil(5 sigma) cells
    assert gauss_1d(100, 12.0).sum() == pytest.approx(1.0)  # capped at half the axis


def test_couplings_in_the_frequency_domain_equal_direct_circular_convolution():
    shape = (12, 16)
    arch = Architecture(
        (Field("a", shape, 5, -5, 4), Field("b", shape, 5, -5, 4, lateral=Lateral(3.0, 1.0, 1.0, 2.0, -0.1))),
        (Input("s", shape),),
        (Coupling("a", "b", 2.0, 1.5, (2, -3)), Coupling("s", "b", -1.0, None, (1, 0)), Coupling("s", "a", 0.5)),
    )
    e = Engine(arch)
    rng = np.random.default_rng(0)
    stim = rng.normal(size=shape)
    e.set_input("s", stim)
    e.groups[0].u[:] = rng.normal(size=e.groups[0].u.shape).astype(np.float32)
    e.groups[0]._outputs()
    fa, fb = e.output("a").astype(np.float64), e.output("b").astype(np.float64)
    e.groups[0].inputs_from_couplings()

    def conv(x, k):
        out = np.zeros(shape)
        for q in np.ndindex(shape):
            out += x[q] * np.roll(k, q, axis=(0, 1))
        return out

    from agents.controllers.dft.fields import lateral_image

    want_b = (conv(fa, kernel_image(shape, 2.0, 1.5, (2, -3))) + conv(stim, kernel_image(shape, -1.0, None, (1, 0)))
              + conv(fb, lateral_image(shape, Lateral(3.0, 1.0, 1.0, 2.0, -0.1))))  # fmt: skip
    np.testing.assert_allclose(e.input_of("b"), want_b, atol=2e-5)
    np.testing.assert_allclose(e.input_of("a"), 0.5 * stim, atol=2e-5)


def test_an_engine_that_keeps_no_inputs_steps_the_same_to_the_bit():
    """A robot's engine writes its fields' inputs over their outputs (2.8 MB less an agent at 210 x 210):
    the same activations and outputs, step for step, with noise, reductions and inputs that change."""
    shape = (24, 20)
    arch = Architecture(
        (Field("a", shape, 5, -5, 4, noise=1.0, lateral=Lateral(3.0, 1.0, 1.0, 2.0)),
         Field("b", shape, 5, -5, 4, noise=1.0, lateral=Lateral(2.0, 1.5)), Field("x", (8,), 3, -5, 4)),
        (Input("s", shape),),
        (Coupling("a", "b", 2.0, 1.5, (2, -3)), Coupling("s", "a", 6.0, 2.0), Coupling("b", "a", -1.0, None, (1, 0)),
         Coupling("b", "x", 2.0, reduce="max")),
    )  # fmt: skip
    kept, lean = Engine(arch), Engine(arch, keep_inputs=False)
    rng = np.random.default_rng(4)
    for step in range(30):
        stim = rng.normal(size=shape) + 2.0
        for e in (kept, lean):
            e.set_input("s", stim)
            e.step(np.uint64(1000 + step))
        for name in ("a", "b", "x"):
            assert kept.u(name).tobytes() == lean.u(name).tobytes()
            assert kept.output(name).tobytes() == lean.output(name).tobytes()
    assert np.abs(kept.input_of("a")).max() > 0.1
    with pytest.raises(ValueError, match="keep_inputs=True"):
        lean.input_of("a")


def test_a_shift_moves_activity_by_its_cells():
    shape = (20, 20)
    shifted = Coupling("s", "b", 1.0, None, (3, -2))
    e = Engine(Architecture((Field("b", shape, 5, -5, 4),), (Input("s", shape),), (shifted,)))
    img = np.zeros(shape)
    img[5, 5] = 1.0
    e.set_input("s", img)
    e.groups[0].inputs_from_couplings()
    assert np.unravel_index(np.argmax(e.input_of("b")), shape) == (8, 3)


def test_the_engines_transforms_are_scipy_fft_bit_for_bit_without_importing_it():
    """agents.controllers.dft.pocketfft calls scipy's compiled pocketfft as scipy.fft does (the same
    numbers) while an agent process never imports scipy (an agent process's 80 MB budget)."""
    import subprocess
    import sys

    import scipy.fft

    from agents.controllers.dft import pocketfft

    assert pocketfft.standalone()
    rng = np.random.default_rng(7)
    cases = [((3, 210, 210), (1, 2)), ((5, 100), (1,)), ((2, 9, 13), (1, 2))]
    cases += [((2, 101, 509), (1, 2)), ((2, 6, 7, 11), (1, 2, 3))]  # prime lengths; three axes
    for shape, axes in cases:
        for dtype in (np.float32, np.float64):
            x = rng.standard_normal(shape).astype(dtype)
            spec = scipy.fft.rfftn(x, axes=axes)
            assert np.array_equal(pocketfft.rfftn(x, axes), spec)
            out = np.empty_like(spec)
            assert pocketfft.rfftn(x, axes, out) is out and np.array_equal(out, spec)
            back = scipy.fft.irfftn(spec, s=shape[1:], axes=axes)
            got = np.empty_like(back)
            pocketfft.irfftn(spec.copy(), shape[1:], axes, got)  # the spectrum is used up
            assert np.array_equal(got, back) and np.array_equal(pocketfft.irfftn(spec.copy(), shape[1:], axes), back)
    from agents.controllers import aot

    aot.build()  # once per source version: an agent process's kernels (else it would fall back to numba)
    child = ("import sys; from swarm.core import kernels; assert kernels.use_ahead_of_time(); "
             "from agents.controllers.arena import make_controller; make_controller('dft'); "
             "print(sorted({m.split('.')[0] for m in sys.modules} & {'scipy', 'numba'}))")  # fmt: skip
    out = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "[]", out.stderr[-2000:]


def test_known_walls_grow_as_scipy_ndimage_dilates_them():
    from scipy.ndimage import binary_dilation

    from agents.controllers.dft.context import grown

    rng = np.random.default_rng(3)
    for shape, density, by in (((50, 70), 0.02, 3), ((210, 210), 0.01, 4), ((5, 5), 0.2, 7), ((1, 9), 0.3, 2)):
        mask = rng.random(shape) < density
        want = binary_dilation(mask, np.ones((2 * by + 1, 2 * by + 1), bool))
        assert np.array_equal(grown(mask, by), want)


def test_pairs_with_the_same_kernel_share_one_transfer_function():
    """The SPA's four directions repeat their kernels: one spectrum each, not one per pair."""
    group = Engine(spa_architecture((60, 80))).groups[0]
    assert len(group.transfer) < len(group.src)
    assert len({row.tobytes() for row in group.transfer}) == len(group.transfer)


def test_an_architecture_that_cannot_be_stepped_is_refused_in_one_line():
    a, b = Field("a", (10,), 5, -5, 4), Field("b", (10, 10), 5, -5, 4)
    with pytest.raises(ValueError, match="joins shapes"):
        Engine(Architecture((a, b), (), (Coupling("a", "b", 1.0),)))
    with pytest.raises(ValueError, match="must be a field or input"):
        Engine(Architecture((a,), (), (Coupling("x", "a", 1.0),)))
    Engine(Architecture((a, b), (), (Coupling("b", "a", 1.0, reduce="max"),)))  # a reduction joins any shapes


def test_field_noise_is_standard_and_keyed():
    a, b = np.empty(200_000, np.float32), np.empty(200_000, np.float32)
    fill_noise(np.uint64(7), a)
    fill_noise(np.uint64(7), b)
    np.testing.assert_array_equal(a, b)
    assert abs(a.mean()) < 0.01 and a.std() == pytest.approx(1.0, abs=0.01)
    fill_noise(np.uint64(8), b)
    assert np.corrcoef(a, b)[0, 1] < 0.01


# ------------------------------------------------------- field dynamics


def _selection_field(n=100):
    """A 1D field with local excitation, broader inhibition and global inhibition (Figure 1)."""
    return Engine(Architecture((Field("u", (n,), 5, -5, 4, 0.5, Lateral(20.0, 3.0, 10.0, 8.0, -0.5)),),
                               (Input("s", (n,)),), (Coupling("s", "u", 1.0),)))  # fmt: skip


def test_two_bumps_make_one_peak_over_the_stronger():
    e = _selection_field()
    x = np.arange(100)
    e.set_input("s", 6.5 * np.exp(-((x - 30) ** 2) / 18) + 5.5 * np.exp(-((x - 70) ** 2) / 18))
    for t in range(300):
        e.step(np.uint64(t))
    u = e.u("u")
    assert u[25:36].max() > 0  # a peak over the stronger bump
    assert u[60:81].max() < 0  # the weaker one is suppressed, though its input alone would lift it
    assert (u > 0).sum() < 15  # one localised peak


def test_a_motivation_peak_is_self_stabilised_but_not_self_sustained():
    shape = (40, 40)
    lat = spa_architecture(shape).fields[0].lateral  # the M fields' kernel
    e = Engine(Architecture((Field("m", shape, 5, -5, 4, 1.0, lat),), (Input("s", shape),),
                            (Coupling("s", "m", 1.0),)))  # fmt: skip
    e.set_input("s", gaussian_2d(shape, 20, 20, 3.0, 4.5))  # alone it would leave the field at -0.5
    centre = []
    for t in range(250):
        e.step(np.uint64(t))
        centre.append(float(e.u("m")[20, 20]))
    assert min(centre[100:]) > 1.5  # the lateral excitation lifts a peak and holds it through the noise
    assert (e.u("m") > 0).sum() < 60  # localised
    e.set_input("s", np.zeros(shape))  # the input goes: the peak decays
    for t in range(250, 350):
        e.step(np.uint64(t))
    assert e.u("m").max() < -2.0


def _bfs(free: np.ndarray, goal) -> np.ndarray:
    d = np.full(free.shape, -1)
    d[goal] = 0
    q = collections.deque([goal])
    while q:
        j, i = q.popleft()
        for dj, di in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            a, b = j + dj, i + di
            if 0 <= a < free.shape[0] and 0 <= b < free.shape[1] and free[a, b] and d[a, b] < 0:
                d[a, b] = d[j, i] + 1
                q.append((a, b))
    return d


SHAPE = (60, 60)
GOAL = (30, 48)


def _two_route_map() -> np.ndarray:
    """A 60 x 60 cell map: the border of the original code and a wall down the middle with gaps at both ends."""
    walls = np.zeros(SHAPE, bool)
    walls[:6] = walls[-5:] = True
    walls[:, :5] = walls[:, -6:] = True
    walls[12:48, 27:33] = True
    return walls


def _planner(walls, position=None) -> Engine:
    e = Engine(spa_architecture(SHAPE))
    e.set_input("goal", gaussian_2d(SHAPE, *GOAL, 3.0, 10.0))
    e.set_input("context", -walls.astype(np.float32))
    if position is not None:
        e.set_input("position", gaussian_2d(SHAPE, *position, 3.0, 1.0))
    return e


def _motivation(e: Engine) -> np.ndarray:
    return np.max([e.u(f"M_{d}") for d in EBS], axis=0)


def test_back_chaining_reaches_the_start_later_on_longer_paths_along_a_shortest_route():
    """The wave moves in steps of delta (5 cells: M -> P and P -> M are both shifted), so its front is a
    chain of islands that fill in later; the route is measured in the covered cells, bridged over gaps of
    up to delta (a closing) and kept off the walls."""
    from scipy.ndimage import binary_closing, binary_dilation

    walls = _two_route_map()
    free = _bfs(~binary_dilation(walls, iterations=2), GOAL)  # path lengths with 2 cells of clearance
    starts = [(50, 40), (10, 15), (36, 10)]  # 28, 55 and 72 cells from the goal
    arrived = {}
    e = _planner(walls)
    reached = np.zeros(SHAPE, bool)  # cells the supra-threshold motivation has covered so far
    for t in range(400):
        e.step(np.uint64(1000 + t))
        reached |= _motivation(e) > 0
        for s in starts:
            if s not in arrived and reached[s]:
                bridged = binary_closing(reached, np.ones((7, 7), bool)) & ~walls
                arrived[s] = (t, _bfs(bridged, GOAL)[s])  # the shortest way inside what the wave covered
    assert set(arrived) == set(starts)
    times = [arrived[s][0] for s in starts]
    assert times == sorted(times) and times[-1] > 2 * times[0]
    for s in starts:
        # a shortest route, within 10% (it may hug the walls closer than the 2-cell clearance of the reference)
        assert 0.85 * free[s] <= arrived[s][1] <= 1.1 * free[s], (s, arrived[s], free[s])


def _intention_near(e: Engine, where, d: str, radius: int = 8) -> float:
    j, i = where
    return float(e.output(f"I_{d}")[j - radius : j + radius + 1, i - radius : i + radius + 1].max())


def test_an_obstacle_on_the_active_route_makes_its_motivation_decay_and_the_other_route_win():
    walls = _two_route_map()
    start = (36, 10)  # nearer the north gap
    e = _planner(walls, position=start)
    for t in range(400):
        e.step(np.uint64(2000 + t))
    gap_north = (slice(49, 54), slice(27, 33))
    assert _intention_near(e, start, "N") > 0.9 and _intention_near(e, start, "S") < 0.1
    assert _motivation(e)[gap_north].max() > 0
    blocked = walls.copy()
    blocked[48:55, 27:33] = True
    e.set_input("context", -blocked.astype(np.float32))
    for t in range(400, 550):
        e.step(np.uint64(2000 + t))
    assert _motivation(e)[gap_north].max() < 0  # the cut route's motivation decays
    for t in range(550, 1000):
        e.step(np.uint64(2000 + t))
    assert _intention_near(e, start, "S") > 0.9 and _intention_near(e, start, "N") < 0.1


def test_release_raises_an_intention_ahead_the_robot_moves_and_satisfaction_forms_at_the_next_place():
    scenario = arena('[[group]]\ncount = 1\ncontroller = "dft"\nstart = [0.15, 0.25, 0.0]\ngoal = [0.4, 0.25]\n',
                     w=0.55, h=0.5, max_ticks=800)  # fmt: skip
    engine = ArenaEngine(scenario)
    c = engine.controllers[0]
    seen_intention = seen_satisfaction = False
    for _ in range(800):
        engine.step()
        x, y, _ = engine.world.pose[0]
        here = (y / 0.01 - 0.5, x / 0.01 - 0.5)
        f_i = c.engine.output("I_E")
        if f_i.max() > 0.5:
            j, i = np.unravel_index(np.argmax(f_i), f_i.shape)
            if not seen_intention and abs(j - here[0]) < 4 and 2 < i - here[1] < 10:
                seen_intention = True  # the intention peak lies just east of the robot, where it will go
        if seen_intention and c.engine.u("C_E")[f_i.shape[0] // 2 - 5 : f_i.shape[0] // 2 + 5].max() > 0:
            seen_satisfaction = True
        if engine.done():
            break
    assert seen_intention and seen_satisfaction
    robot = engine.summary()["robots"][0]
    assert robot["reached"] and robot["distance"] > 0.2


# ------------------------------------------------------------- the robot


def test_the_e_puck_interface_follows_the_original_code():
    iface = Interface()
    lw, rw = wheel_profiles(iface)
    assert (round(lw[49], 1), round(rw[49], 1)) == (416.5, 433.0)  # cell 50 (1-based), as parameters.md says
    head = heading_images(iface, np.pi / 2)  # facing north: the north action field's input peaks at cell 50
    assert int(np.argmax(head["N"])) == 49 and head["N"].max() == pytest.approx(4.0)
    assert int(np.argmax(head["E"])) > 49  # east lies to the robot's right: cells above 50
    ir = ir_image(iface, np.array([1000.0, 0, 0, 0, 0, 0, 0, 0]))  # ps0, front right
    assert int(np.argmax(ir)) == 54 and ir.max() == pytest.approx(5 * np.log1p(1000 / 50))
    one = {d: np.zeros(100) for d in EBS}
    one["N"][60] = 1.0  # a peak right of straight ahead turns the robot right
    left, right = wheel_speeds(iface, one)
    assert left > right and abs(left - right) <= 400


def test_the_robot_reaches_its_goal_in_the_z_maze():
    s = load_scenario("zmaze").with_overrides(controller="dft", noise="low", seed=1)
    summary = ArenaEngine(s).run()
    r = summary["robots"][0]
    assert r["reached"] and r["collisions"] == 0
    assert 1.0 <= r["path_ratio"] < 1.3
    assert 150 < r["ticks_to_goal"] < 1200  # it plans first (about 200 steps in the paper), then drives


def test_snapshot_and_restore_continue_bit_for_bit():
    s = load_scenario("zmaze").with_overrides(controller="dft", noise="high", max_ticks=260)
    engine = ArenaEngine(s)
    engine.step(220)
    state = json.loads(json.dumps(engine.controllers[0].snapshot(), default=lambda a: a.tolist()))
    perceptions = [engine.world.perceive_all()[0] for _ in range(1)]
    twin = DftController()
    from world_server.arena.scenario import controller_params

    twin.reset(s.seed, 0, controller_params(s, 0))
    twin.restore(state)
    for _ in range(30):
        np.testing.assert_array_equal(engine.controllers[0].step(perceptions[0]), twin.step(perceptions[0]))
    np.testing.assert_array_equal(engine.controllers[0].engine.u("M_N"), twin.engine.u("M_N"))


def test_told_obstacles_enter_the_map_while_present():
    body = ('[[obstacle]]\nrect = [0.3, 0.3, 0.4, 0.4]\nappear = 5\nvanish = 10\n'
            '[[group]]\ncount = 1\ncontroller = "dft"\nstart = [0.15, 0.15, 0.0]\ngoal = [0.8, 0.8]\n')  # fmt: skip
    scenario = arena(body, max_ticks=20)
    engine = ArenaEngine(scenario)
    c = engine.controllers[0]
    inside = (35, 35)
    seen = []
    for _ in range(12):
        engine.step()
        seen.append(c.map_base[inside])
    assert seen[:5] == [0.0] * 5 and seen[5:10] == [-1.0] * 5 and seen[10:] == [0.0] * 2
    unknown = parse_scenario_text(box(body + '[dft]\nobstacles = "unknown"\n', max_ticks=20), "u.toml")
    engine = ArenaEngine(unknown)
    engine.step(8)
    assert engine.controllers[0].map_base[inside] == 0.0


def test_a_bad_dft_table_is_refused_in_one_line():
    with pytest.raises(ValueError, match=r"\[dft\]: unknown field 'speed'"):
        DftParams.from_table({"speed": 1})
    with pytest.raises(ValueError, match="obstacles is 'told', 'sensed' or 'unknown'"):
        DftParams.from_table({"obstacles": "psychic"})
    with pytest.raises(ScenarioError, match="dft"):
        parse_scenario_text(box('[[group]]\ncount = 1\ncontroller = "dft"\n[dft]\ncell = "big"\n'), "bad.toml")
    with pytest.raises(ScenarioError, match="ir"):  # the animat has no IR sensors
        parse_scenario_text(box('[[group]]\ncount = 1\ncontroller = "dft"\nrobot = "animat"\n', w=3, h=3), "a.toml")


def test_travel_directions_match_the_shifts():
    """The north EB back-chains southwards: its motivation spreads opposite its travel."""
    assert TRAVEL["N"] == (1, 0) and TRAVEL["E"] == (0, 1)


# ------------------------------------------------------------ distributed


def test_lockstep_dft_equals_in_process_bit_for_bit():
    from tests.distributed import run_world

    scenario = load_scenario("zmaze").with_overrides(controller="dft", noise="high", seed=2, max_ticks=240)
    engine = ArenaEngine(scenario)
    expected = engine.run()
    summary, world = run_world(scenario, "dft-lockstep", [("dft", 1, 1)], deadline=60.0)
    np.testing.assert_array_equal(world.pose, engine.world.pose)
    assert summary["robots"] == expected["robots"] and summary["rejected_messages"] == 0


def test_a_recording_holds_the_fields_the_intentions_and_the_optimum(tmp_path):
    from swarm.recording.arena import ArenaRecorder

    s = load_scenario("zmaze").with_overrides(controller="dft", max_ticks=60)
    engine = ArenaEngine(s)
    path = tmp_path / "dft.rrd"
    recorder = ArenaRecorder(path, engine.world, engine.goals, {"run_id": "dft"}, controllers=engine.controllers)
    recorder.close(engine.run(recorder=recorder))
    rows = rrd_rows(path)
    for d in EBS:
        assert rows[f"fields/0/M/{d}"] == rows[f"fields/0/I/{d}"] == 3  # ticks 0, 20, 40
        assert rows[f"fields/0/intention/{d}"] == rows[f"fields/0/action/{d}"] == 60
    assert rows["world/optimum/0"] == 1


# ------------------------------------------------------- sensing and sharing


def test_a_robot_marks_what_its_sensors_meet_off_the_map_and_the_others_receive_it():
    body = ('[[obstacle]]\nrect = [0.3, 0.1, 0.34, 0.4]\n'
            '[[group]]\ncount = 2\ncontroller = "dft"\nstarts = [[0.15, 0.25, 0.0], [0.15, 0.8, 0.0]]\n'
            'goals = [[0.6, 0.25], [0.6, 0.8]]\n[dft]\nobstacles = "sensed"\n')  # fmt: skip
    engine = ArenaEngine(arena(body, w=1.0, h=1.0, max_ticks=400))
    a, b = engine.controllers
    engine.step(400)
    x_face = int(0.3 / 0.01)
    mine, theirs = a.sensed.blocked(a.tick), b.sensed.blocked(b.tick)
    assert mine[15:35, x_face - 3 : x_face + 3].sum() > 10  # robot 0 met the box's west face and marked it
    assert theirs[15:35, x_face - 3 : x_face + 3].sum() > 10  # and robot 1 got it over the context key space
    assert b.received > 0 and engine.shares.of(0)["messages"] > 0
    marked = np.argwhere(mine)  # every mark lies on the box, within a mark's radius (4 cells) of its faces
    rows, cols = marked[:, 0], marked[:, 1]
    assert ((rows >= 10 - 5) & (rows < 40 + 5) & (cols >= 30 - 5) & (cols < 34 + 5)).all()


def test_malformed_context_is_refused_whole():
    from agents.controllers.arena import deliver

    s = load_scenario("zmaze").with_overrides(agents=2, controller="dft")
    from dataclasses import replace

    s = replace(s, controller_params={"dft": {"obstacles": "sensed"}})
    engine = ArenaEngine(s)
    c = engine.controllers[1]
    bad_ones = (
        {"tick": 1, "marked": [1], "cleared": []},
        {"tick": 1, "marked": [5, 99999], "cleared": []},
        {"tick": "x", "marked": [], "cleared": []},
        [1, 2],
        {"tick": 1, "marked": [1.5, 2], "cleared": []},
    )
    for bad in bad_ones:
        with pytest.raises(ValueError):
            c.receive(0, bad)
    assert not c.sensed.blocked(1).any()
    from swarm.core.wire import pack

    assert deliver(engine.controllers, [0, 1], [(0, "context", b"\xc1garbage"), (0, "context", pack({"tick": 0}))]) == 2


def test_lockstep_sharing_dft_robots_equal_in_process_bit_for_bit():
    from swarm.experiments.billing2015.dft import together_scenario
    from tests.distributed import run_world

    scenario = together_scenario("scout-sensed", 40, 500, "low", 3, 280)
    engine = ArenaEngine(scenario)
    engine.run()
    assert engine.shares.of(1)["messages"] > 0  # the scout met the box and wrote it
    summary, world = run_world(scenario, "dft-share", [("dft", 2, 1)], deadline=60.0)
    np.testing.assert_array_equal(world.pose, engine.world.pose)
    assert [r.get("shared") for r in summary["robots"]] == [engine.shares.of(a) for a in (0, 1)]
    assert summary["rejected_messages"] == 0


# ------------------------------------------------------------- experiments


def test_runs_are_classified_by_the_route_they_took():
    from swarm.experiments.billing2015.dft import classify

    assert classify(np.array([0.6, 0.65, 0.72, 0.8, 0.6])) == "north"
    assert classify(np.array([0.6, 0.55, 0.5, 0.3, 0.6])) == "south"
    assert classify(np.array([0.6, 0.72, 0.6, 0.5, 0.3])) == "north-then-south"
    assert classify(np.array([0.6, 0.62, 0.58])) == "neither"


def test_case_tables_put_the_papers_f_beside_ours(tmp_path):
    from swarm.experiments.billing2015.dft import run_dft_experiment, summarise_pairs

    rows = [{"scenario": "zmaze", "controller": c, "noise": n, "pair": k, "reached": True, "ticks_to_goal": 300 + k,
             "path_ratio": (1.1 if c == "dft" else 1.0) + 0.01 * k, "collisions": 0}
            for c, n in (("dft", "low"), ("dft", "high"), ("carrot", "none"), ("carrot", "low"), ("carrot", "high"))
            for k in range(5)]  # fmt: skip
    summary, md = summarise_pairs(rows)
    assert [r["condition"] for r in summary] == ["SPA-LN", "SPA-HN", "FTC-NN", "FTC-LN", "FTC-HN"]
    assert "paper F = 0.97" in md and "| SPA-LN | 5/5 | 1.120 ± 0.016 | 302 |" in md
    result = run_dft_experiment("dft-case1", None, 1, 1, 0, tmp_path, noise="high", progress=False)
    assert (tmp_path / "plot.png").exists() and "| SPA-HN | 1/1 |" in result["markdown"]


def test_the_swarm_summary_measures_how_much_earlier_robot_0_replans():
    from swarm.experiments.billing2015.dft import replan_tick, summarise_together

    def row(c, k, route, south, turn):
        return {"condition": c, "run": k, "route": route, "south_tick": south, "turn_tick": turn, "reached": True,
                "ticks_to_goal": 900, "appear": 100, "duration": 600}  # fmt: skip

    rows = [
        row("alone-told", 1, "south", 300, 270),
        row("alone-told", 2, "south", 300, 270),
        row("alone-sensed", 1, "north-then-south", 800, 700),
        row("alone-sensed", 2, "north", None, 650),
        row("scout-sensed", 1, "north-then-south", 550, 430),
        row("scout-sensed", 2, "north-then-south", 560, 440),
    ]
    assert replan_tick(rows[2]) == 700 and replan_tick(rows[3]) is None and replan_tick(rows[0]) == 300
    summary, md = summarise_together(rows)
    last = summary[-1]
    assert (last["south_alone"], last["south_scout"], last["sooner_with_scout"]) == (1, 2, 2)
    assert last["median_ticks_earlier"] == 270 and "a median of 270 ticks earlier" in md


def test_cases_1_and_2_run_on_a_floor_and_pairs_given_and_refuse_bad_ones_in_one_line(tmp_path):
    """`--scenario FILE` (pairs drawn from the seed on that floor) and `--pairs FILE` (runs.csv is one)."""
    import csv
    import re
    from pathlib import Path

    from swarm.experiments.billing2015.dft import run_dft_experiment

    floor = tmp_path / "hall.toml"  # the Z-maze without its middle bar: a floor the paper never used
    zmaze = (Path(__file__).parents[1] / "swarm" / "scenarios" / "zmaze.toml").read_text()
    kept = [block for block in zmaze.split("[[wall]]") if 'name = "z_middle_bar"' not in block]
    floor.write_text("[[wall]]".join(kept).replace('name = "zmaze"', 'name = "hall"'))
    drawn = run_dft_experiment("dft-case2", str(floor), 1, 1, 5, tmp_path / "drawn", noise="low", max_ticks=40,
                               progress=False)  # fmt: skip
    rows = list(csv.DictReader((tmp_path / "drawn" / "runs.csv").read_text().splitlines()))
    assert {r["scenario"] for r in rows} == {str(floor)} and len({r["pair"] for r in rows}) == 1
    assert "in " + str(floor) in drawn["markdown"] and "drawn from seed 5" in drawn["markdown"]
    given = run_dft_experiment("dft-case1", None, None, 1, 0, tmp_path / "given", noise="low", max_ticks=40,
                               progress=False, pairs=str(tmp_path / "drawn" / "runs.csv"))  # fmt: skip
    again = list(csv.DictReader((tmp_path / "given" / "runs.csv").read_text().splitlines()))
    assert {(r["start_x"], r["goal_y"]) for r in again} == {(r["start_x"], r["goal_y"]) for r in rows}
    assert "in zmaze" in given["markdown"]
    (tmp_path / "bad.csv").write_text("x,y\n1,2\n")
    for kwargs, words in [({"pairs": str(tmp_path / "bad.csv")}, "needs a header with start_x"),
                          ({"scenario": "setup1"}, "runs on an arena floor"),
                          ({"pairs": str(tmp_path / "nowhere.csv")}, "cannot read it")]:  # fmt: skip
        case = "dft-case2"
        with pytest.raises(ScenarioError, match=re.escape(words)) as e:
            run_dft_experiment(case, kwargs.get("scenario"), 1, 1, 0, tmp_path / "bad", pairs=kwargs.get("pairs"),
                               progress=False)  # fmt: skip
        assert "\n" not in str(e.value)
    with pytest.raises(ScenarioError, match="dft-case3 runs on zmaze"):
        run_dft_experiment("dft-case3", str(floor), 1, 1, 0, tmp_path / "bad", progress=False)
