"""swarm.envs: the arena as a PettingZoo ParallelEnv and a Gymnasium env (docs/envs.md)."""

from __future__ import annotations

import numpy as np
import pytest

from swarm.envs import make, parallel_env
from swarm.scenario import parse_arena_text
from tests.arena_helpers import box

GOAL_PAIR = """
[[group]]
count = 1
controller = "carrot"
start = [0.3, 0.3, 0.0]
goal = [0.3, 0.3]
[[group]]
count = 1
controller = "carrot"
start = [0.7, 0.7, 0.0]
goal = [0.2, 0.8]
"""


def goal_pair():
    """Two e-pucks in a box: robot_0 starts on its goal (a dwell of one tick), robot_1 far from its own."""
    return parse_arena_text("goal_radius = 0.05\ngoal_dwell = 1\n" + box(GOAL_PAIR), "pair.toml")


def ten_epucks(**kw):
    """Ten e-pucks with their IR sensors in the Z-maze, goals drawn."""
    return parallel_env("zmaze", agents=10, **kw)


def random_actions(env, rng) -> dict[str, np.ndarray]:
    return {a: rng.uniform(-0.2, 0.2, 2).astype(np.float32) for a in env.agents}


def test_parallel_api():
    from pettingzoo.test import parallel_api_test

    env = ten_epucks(max_ticks=60)
    assert env.possible_agents == [f"robot_{a}" for a in range(10)]
    assert "ir" in env.observation_space("robot_0").spaces
    parallel_api_test(env, num_cycles=80)


# unbounded readings (odometry, position) are honest; the env is made by swarm.envs.make, not gymnasium.make
@pytest.mark.filterwarnings("ignore:.*infinity:UserWarning", "ignore:.*not having a spec:UserWarning")
def test_gymnasium_checker():
    from gymnasium.utils.env_checker import check_env

    env = make("zmaze", max_ticks=50)
    check_env(env.unwrapped)
    obs, _ = env.reset(seed=1)
    assert env.observation_space.contains(obs)


def test_same_seed_same_observations_and_trajectory():
    env = ten_epucks(max_ticks=100)
    runs = []
    for _ in range(2):
        obs, _ = env.reset(seed=3)
        rng, frames = np.random.default_rng(5), [obs]
        for _ in range(30):
            frames.append(env.step(random_actions(env, rng))[0])
        runs.append(frames)
    for a, b in zip(*runs, strict=True):
        assert a.keys() == b.keys()
        for name in a:
            for key in a[name]:
                np.testing.assert_array_equal(a[name][key], b[name][key])
    other, _ = env.reset(seed=4)
    assert any(not np.array_equal(other[n]["position"], runs[0][0][n]["position"]) for n in other)


def test_a_robot_at_its_goal_leaves_the_agents():
    env = parallel_env(goal_pair())
    env.reset(seed=0)
    _, _, terms, truncs, _ = env.step({a: np.zeros(2, np.float32) for a in env.agents})
    assert terms == {"robot_0": True, "robot_1": False} and not any(truncs.values())
    assert env.agents == ["robot_1"]
    with pytest.raises(ValueError, match="robot_0: not a live agent"):
        env.step({"robot_0": np.zeros(2)})


def test_reward_and_terminated_functions_and_truncation():
    def reward(world, a, info):
        info["x"] = float(world.pose[a, 0])
        return -float(a)

    env = parallel_env(goal_pair(), reward=reward, terminated=lambda world, a: False, max_ticks=3)
    env.reset()
    for tick in range(3):
        _, rewards, terms, truncs, infos = env.step({a: np.full(2, 0.05) for a in env.agents})
        assert rewards == {"robot_0": 0.0, "robot_1": -1.0} and not any(terms.values())
        assert all(truncs.values()) == (tick == 2) and "x" in infos["robot_1"]
    assert env.agents == []


def test_nan_refused_and_over_limit_clipped():
    env = ten_epucks()
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"^robot_2: wheel speeds must be finite"):
        env.step({a: np.array([np.nan, 0.0]) if a == "robot_2" else np.zeros(2) for a in env.agents})
    start = env.state()
    env.step({a: np.full(2, 10.0) for a in env.agents})
    assert sum(env.run.world.rejected.values()) == 0
    assert np.all(np.hypot(*(env.state()[:, :2] - start[:, :2]).T) > 0)


def test_grid_scenario_refused():
    with pytest.raises(ValueError, match="arena scenarios only"):
        parallel_env("maze")


def test_single_robot_env_drives_the_others_by_their_controllers():
    env = make("zmaze", agent=1, agents=3, render_mode="rgb_array", max_ticks=40)
    env.reset(seed=2)
    start = env.unwrapped.run.world.pose.copy()
    for _ in range(20):
        obs, _, terminated, truncated, _ = env.step(np.zeros(2, np.float32))
        assert env.observation_space.contains(obs) and not (terminated or truncated)
    moved = np.hypot(*(env.unwrapped.run.world.pose[:, :2] - start[:, :2]).T)
    assert moved[1] == 0 and moved[0] > 0 and moved[2] > 0
    image = env.render()
    assert image.shape == (400, 400, 3) and image.dtype == np.uint8


def test_wrong_shape_refused_in_one_line():
    env = ten_epucks()
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"^robot_1: expected 2 wheel speeds, got shape \(3,\)$"):
        env.step({a: np.zeros(3) if a == "robot_1" else np.zeros(2) for a in env.agents})


def test_pettingzoo_seed_test():
    from pettingzoo.test import parallel_seed_test

    parallel_seed_test(lambda: ten_epucks(max_ticks=40), num_cycles=60)


def test_observations_are_the_worlds_readings():
    env = ten_epucks(render_mode="rgb_array")
    obs, _ = env.reset(seed=1)
    env.step({a: np.full(2, 0.05) for a in env.agents})
    obs = env.step({a: np.full(2, 0.05) for a in env.agents})[0]
    readings = env.run.world.perceive()
    for a, name in enumerate(env.possible_agents):
        assert obs[name].keys() == readings[a].keys()
        for key, value in readings[a].items():
            np.testing.assert_array_equal(obs[name][key], value)
    assert env.render().shape == (400, 400, 3)


ANIMAT_AT_FOOD = """[metabolism]
[[resource]]
name = "food"
kind = "ingesting"
centre = [0.6, 0.5]
[[group]]
count = 1
controller = "bg"
robot = "animat"
start = [1.2, 0.5, 0.0]
"""

TALKERS = """[[group]]
count = 2
controller = "wander"
starts = [[0.4, 0.5, 0.0], [0.6, 0.5, 3.14159]]
robot = { model = "epuck", sensors = ["range_and_bearing"] }
"""


def test_a_learner_chooses_the_metabolisms_act():
    from swarm.envs.spaces import ACTS

    env = parallel_env(parse_arena_text(box(ANIMAT_AT_FOOD, w=3.0, h=2.0, robot="animat"), "food.toml"))
    space = env.action_space("robot_0")
    assert set(space.spaces) == {"wheels", "act"} and space["act"].n == len(ACTS)
    env.reset(seed=0)
    still = np.zeros(2, np.float32)
    env.step({"robot_0": {"wheels": still, "act": 0}})
    assert env.run.world.metabolism.acts[0].sum() == 0
    for _ in range(3):
        env.step({"robot_0": {"wheels": still, "act": ACTS.index("ReloadEp")}})  # in the food's zone: it eats
    assert env.run.world.metabolism.acts[0, ACTS.index("ReloadEp")] == 3
    with pytest.raises(ValueError, match=r"^robot_0: act must be a whole number from 0 to 2 .*got 7$"):
        env.step({"robot_0": {"wheels": still, "act": 7}})
    with pytest.raises(ValueError, match=r"^robot_0: its robot has no range_and_bearing sensor to broadcast with$"):
        env.step({"robot_0": {"wheels": still, "broadcast": b"hi"}})
    with pytest.raises(ValueError, match=r"^robot_0: unknown action keys \['speed'\]"):
        env.step({"robot_0": {"wheels": still, "speed": 1}})


def test_a_learner_broadcasts_and_its_neighbour_hears_it_next_tick():
    from pettingzoo.test import parallel_api_test

    env = parallel_env(parse_arena_text(box(TALKERS), "talk.toml"))
    assert env.action_space("robot_0")["broadcast"].shape == (4,)
    parallel_api_test(env, num_cycles=20)  # sampled dict actions, broadcasts included
    env.reset(seed=0)
    still = np.zeros(2, np.float32)
    env.step({"robot_0": {"wheels": still, "broadcast": np.array([1, 2, 3, 4], np.uint8)}, "robot_1": still})
    heard = env.step({"robot_0": still, "robot_1": still})[0]["robot_1"]
    assert heard["rab_count"] == 1 and heard["rab_data"][0].tolist() == [1, 2, 3, 4]
    with pytest.raises(ValueError, match=r"^robot_1: broadcast must be bytes or a 1-D array of 0-255"):
        env.step({"robot_1": {"wheels": still, "broadcast": np.array([300, 1])}})
