"""Robot bodies (world_server/grid/bodies.py): ideal moves and pymunk discs."""

from dataclasses import replace

import numpy as np
import pytest

from swarm.core.errors import ScenarioError
from swarm.engines.grid import Engine
from swarm.scenario import load_scenario, parse_scenario_text
from world_server import persist
from world_server.grid.bodies import Bodies
from world_server.grid.face.layout import A_MOVE, ACT_LEN, STAY
from world_server.grid.params import PhysicsParams
from world_server.grid.world import GridWorld

N, E, S, W = 0, 1, 2, 3
CORRIDOR = np.zeros((3, 9), dtype=bool)
CORRIDOR[0, :] = CORRIDOR[2, :] = True  # a one-cell-wide corridor along row 1


def _acts(moves):
    acts = np.zeros((len(moves), ACT_LEN), dtype=np.int64)
    acts[:, A_MOVE] = moves
    return acts


def _physical(**kw) -> PhysicsParams:
    return PhysicsParams(mode="physical", **kw)


def test_a_lone_body_arrives_within_the_tick_like_an_ideal_move():
    bodies = Bodies(_physical(), CORRIDOR, 1, (1, 1))
    pos = np.array([[1, 1]])
    for _ in range(5):
        acts = _acts([E])
        bodies.move(pos, acts)
        assert acts[0, A_MOVE] == E
        pos[0, 1] += 1
        assert np.hypot(*(bodies.xy[0] - (pos[0, 1] + 0.5, 1.5))) <= bodies.params.arrive
    assert bodies.blocked_moves == 0 and bodies.blocked_seconds == 0.0
    assert bodies.sim_seconds == pytest.approx(5 * 0.5, abs=0.3)  # a cell at 2 cells/s, plus a step to start


def test_robots_meeting_head_on_keep_right_and_pass_each_other():
    bodies = Bodies(_physical(), CORRIDOR, 2, (1, 1))
    bodies.place(np.array([[3.5, 1.5], [4.5, 1.5]]))
    acts = _acts([E, W])  # they swap cells through a one-cell corridor
    bodies.move(np.array([[1, 3], [1, 4]]), acts)
    assert list(acts[:, A_MOVE]) == [E, W]
    assert bodies.blocked_seconds > 0  # they met, sidestepped, and went on


def test_robots_too_wide_to_pass_block_each_other_and_both_moves_fail():
    bodies = Bodies(_physical(diameter=0.7), CORRIDOR, 2, (1, 1))
    bodies.place(np.array([[3.5, 1.5], [4.5, 1.5]]))
    acts = _acts([E, W])
    bodies.move(np.array([[1, 3], [1, 4]]), acts)
    assert list(acts[:, A_MOVE]) == [STAY, STAY]
    assert bodies.blocked_moves == 2
    assert bodies.blocked_seconds > 2 * 1.5  # most of the 2 s tick, for each of them
    assert bodies.sim_seconds == pytest.approx(bodies.params.timeout)
    assert np.hypot(*(bodies.xy[0] - bodies.xy[1])) >= 0.7 - 0.02  # they touch; they do not pass through


def test_a_queue_follows_its_leader_and_nobody_enters_a_wall():
    bodies = Bodies(_physical(diameter=0.8), CORRIDOR, 3, (1, 1))
    bodies.place(np.array([[3.5, 1.5], [2.5, 1.5], [1.5, 1.5]]))
    pos = np.array([[1, 3], [1, 2], [1, 1]])
    for _ in range(4):
        acts = _acts([E, E, E])
        bodies.move(pos, acts)
        pos[acts[:, A_MOVE] == E, 1] += 1
        xy = bodies.xy
        assert np.all(np.abs(xy[:, 1] - 1.5) <= 0.5 - 0.4 + 0.02)  # squeezed between the corridor's walls
        for i in range(3):
            for j in range(i + 1, 3):
                assert np.hypot(*(xy[i] - xy[j])) >= 0.8 - 0.02
    assert list(pos[:, 1]) == [7, 6, 5]  # all advanced four cells, in order


def test_moves_into_walls_are_left_for_the_grid_to_reject():
    bodies = Bodies(_physical(), CORRIDOR, 1, (1, 1))
    acts = _acts([N])
    bodies.move(np.array([[1, 1]]), acts)
    assert acts[0, A_MOVE] == N and bodies.blocked_moves == 0


def test_ideal_bodies_are_cell_centres_and_never_simulate():
    bodies = Bodies(PhysicsParams(), CORRIDOR, 2, (1, 1))
    acts = _acts([E, W])
    bodies.move(np.array([[1, 3], [1, 5]]), acts)
    assert list(acts[:, A_MOVE]) == [E, W]
    np.testing.assert_array_equal(bodies.positions(np.array([[1, 3], [2, 0]])), [[3.5, 1.5], [0.5, 2.5]])
    assert bodies.summary(2) == {"physics": "ideal"}


def test_one_physical_agent_runs_exactly_the_ideal_run():
    """Without congestion every move arrives in time: the paper's semantics."""
    base = load_scenario("setup2").with_overrides(agents=1, seed=4)
    ideal = Engine(base).run().summary
    physical = Engine(base.with_overrides(physics="physical")).run().summary
    for key in ("iterations", "delivered", "explored_cells", "optimal_cells"):
        assert physical[key] == ideal[key], key
    assert physical["blocked_moves"] == 0


def test_a_physical_swarm_finishes_deterministically_and_reports_blocking():
    scenario = load_scenario("maze").with_overrides(agents=8, seed=2, physics="physical")
    a, b = Engine(scenario), Engine(scenario)
    sa, sb = a.run().summary, b.run().summary
    assert sa["finished"]
    for key in ("iterations", "sim_seconds", "blocked_seconds", "blocked_moves"):
        assert sa[key] == sb[key], key
    np.testing.assert_array_equal(a.world.body_xy, b.world.body_xy)
    assert sa["physics"] == "physical" and sa["blocked_seconds"] > 0
    assert 0 < sa["blocked_share"] < 1


def test_body_positions_survive_a_save_and_a_resume(tmp_path):
    scenario = load_scenario("maze").with_overrides(agents=4, seed=1, physics="physical")
    engine = Engine(scenario)
    engine.step(30)
    path = tmp_path / "s.npz"
    persist.save(path, engine.world, engine.tick, np.zeros(4, np.int64), {}, scenario.describe())
    state = persist.load(path)
    fresh = GridWorld(scenario)
    fresh.bodies.place(state["body_xy"])
    np.testing.assert_array_equal(fresh.body_xy, engine.world.body_xy)


def test_a_lost_body_stops_blocking_and_a_new_one_starts_at_the_base():
    world = GridWorld(load_scenario("maze").with_overrides(agents=2, physics="physical"))
    world.remove_body(0)
    assert world.bodies._shapes[0].filter.categories == 0
    world.new_body(0)
    assert world.bodies._kind[0] == "nest"
    np.testing.assert_array_equal(world.body_xy[0], (world.base[1] + 0.5, world.base[0] + 0.5))


@pytest.mark.parametrize(
    ("physics", "message"),
    [('mode = "wobbly"', "physics.mode"), ("diameter = 1.0", "physics.diameter"), ("speed = -1", "physics.speed"),
     ("timeout = 0.1", "physics.timeout"), ("dt = 0", "physics.dt"), ("arrive = 0.7", "physics.arrive"),
     ("diameter = nan", "physics"), ('colour = "red"', "physics]: colour"), ('speed = "fast"', "physics.speed")],
)  # fmt: skip
def test_bad_physics_sections_are_refused_with_the_field(physics, message):
    text = f'[map]\nascii = """\n#####\n#B.R#\n#####\n"""\n[physics]\n{physics}\n'
    with pytest.raises(ScenarioError, match=message.replace("[", r"\[").replace("]", r"\]")):
        parse_scenario_text(text, "p.toml")


def test_physics_from_the_scenario_file_and_the_command_line():
    text = '[map]\nascii = """\n#####\n#B.R#\n#####\n"""\n[physics]\nmode = "physical"\ndiameter = 0.3\n'
    s = parse_scenario_text(text, "p.toml")
    assert s.physics == replace(PhysicsParams(), mode="physical", diameter=0.3)
    assert s.with_overrides(physics="ideal", body_diameter=0.7).physics.diameter == 0.7
    with pytest.raises(ScenarioError, match=r"physics\.diameter"):
        s.with_overrides(body_diameter=2.0)
    assert s.describe()["physics"]["mode"] == "physical"


def test_the_base_is_a_nest_and_robots_leave_it_one_after_another():
    field = np.zeros((5, 5), dtype=bool)
    bodies = Bodies(_physical(), field, 30, (2, 2))  # 30 discs overlapping on one cell: fine in the nest
    acts = _acts([E] * 30)  # everybody heads for the same exit cell
    bodies.move(np.tile([2, 2], (30, 1)), acts)
    out = np.flatnonzero(acts[:, A_MOVE] == E)
    assert 1 <= len(out) <= 3 and out[0] == 0  # a few, admitted in id order
    for i in out:
        for j in out[out > i]:
            assert np.hypot(*(bodies.xy[i] - bodies.xy[j])) >= 0.9 * bodies.params.diameter


def test_a_robot_whose_move_failed_senses_it_next_tick():
    from world_server.grid.face.layout import BLOCKED, new_perception

    text = '[map]\nascii = """\n#######\n#B...R#\n#######\n"""\n[physics]\nmode = "physical"\ndiameter = 0.7\n'
    world = GridWorld(parse_scenario_text(text, "c.toml").with_overrides(agents=2))
    world.bodies.place(np.array([[2.5, 1.5], [3.5, 1.5]]))
    world.pos[:] = [[1, 2], [1, 3]]
    world.acts[:, A_MOVE] = [E, W]  # too wide to pass each other
    world.resolve(0)
    np.testing.assert_array_equal(world.pos, [[1, 2], [1, 3]])
    np.testing.assert_array_equal(world.blocked, [1, 1])
    pi, pf = new_perception()
    world.perceive(0, pi, pf)
    assert pi[BLOCKED] == 1
    world.acts[:, A_MOVE] = [W, E]  # apart: both arrive, nothing to sense
    world.resolve(1)
    np.testing.assert_array_equal(world.blocked, [0, 0])


def test_80_bodies_on_setup1_forage_without_jamming():
    # seed 2 jammed (20,000 ticks, 89% of the time blocked) when a blocked climber also
    # forgot its climb; with the climb kept it finishes in about 500 ticks
    scenario = load_scenario("setup1").with_overrides(agents=80, seed=2, physics="physical")
    summary = Engine(scenario).run("foraged", 5000).summary
    assert summary["finished"] and summary["blocked_share"] < 0.3, summary


def test_a_body_pushed_around_a_corner_finds_its_way_back_along_the_grid():
    rows = ["#######", "#B....#", "####.##", "#.....#", "#######"]
    walls = np.array([[ch == "#" for ch in row] for row in rows])
    bodies = Bodies(_physical(), walls, 1, (1, 1))
    bodies.place(np.array([[2.5, 3.5]]))  # in cell (3, 2); its robot's cell is (1, 2), behind the wall at (2, 2)
    pos = np.array([[1, 2]])
    for _ in range(4):  # 6 cells round the wall at 2 cells/s, 2 s per tick at most
        bodies.move(pos, _acts([STAY]))
        if np.hypot(*(bodies.xy[0] - (2.5, 1.5))) <= bodies.params.arrive:
            break
    assert np.hypot(*(bodies.xy[0] - (2.5, 1.5))) <= bodies.params.arrive, bodies.xy[0]  # not stuck on the wall
