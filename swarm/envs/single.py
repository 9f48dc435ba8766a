"""One robot of an arena scenario as a Gymnasium env; the scenario's other robots, if any, are
driven by their own controllers (swarm.envs.drivers), as a run of the scenario would drive them."""

from __future__ import annotations

from typing import Any, ClassVar

import gymnasium as gym
import numpy as np

from swarm.envs.drivers import Drivers
from swarm.envs.parallel import Reward, Terminated, no_reward
from swarm.envs.render import Canvas
from swarm.envs.run import ArenaRun, agent_boxes
from swarm.envs.source import arena_scenario
from world_server.arena.scenario import ArenaScenario


class ArenaGymEnv(gym.Env):
    """Robot `agent`'s observation (a Dict of its readings) and wheel speeds.  The episode ends when
    `terminated(world, agent)` (by default: its robot finished or left the world), or is truncated at
    `max_ticks`."""

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["rgb_array"]}

    def __init__(self, scenario: ArenaScenario, *, agent: int = 0, reward: Reward | None = None,
                 terminated: Terminated | None = None, max_ticks: int | None = None, seed: int | None = None,
                 render_mode: str | None = None):  # fmt: skip
        if not 0 <= agent < scenario.agents:
            raise ValueError(f"agent: expected a robot from 0 to {scenario.agents - 1}, got {agent}")
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode: expected None or 'rgb_array', got {render_mode!r}")
        self.scenario, self.agent = scenario, agent
        self.reward_fn = reward or no_reward
        self.terminated_fn = terminated
        self.max_ticks = scenario.max_ticks if max_ticks is None else max_ticks
        self.render_mode = render_mode
        obs, act = agent_boxes(scenario)
        self.boxes = obs
        self.observation_space, self.action_space = obs[agent], act[agent]
        self.first_seed: int | None = scenario.seed if seed is None else seed
        self.run: ArenaRun | None = None
        self.canvas = Canvas()
        self.drivers: Drivers | None = None

    def reset(self, *, seed: int | None = None, options: dict | None = None) -> tuple[dict, dict]:
        """A fresh world: under `seed`, else the env's seed on the first reset and a draw of its
        generator (np_random) after."""
        if seed is None and self.first_seed is not None:
            seed = self.first_seed
        self.first_seed = None
        super().reset(seed=seed)
        world_seed = int(seed) if seed is not None else int(self.np_random.integers(2**31 - 1))
        self.run = ArenaRun(self.scenario, world_seed, self.boxes)
        others = [a for a in range(self.scenario.agents) if a != self.agent]
        self.drivers = Drivers(self.run, others) if others else None
        return self.run.observe()[self.agent], {}

    def step(self, action: Any) -> tuple[dict, float, bool, bool, dict]:
        run = self.run
        if run is None:
            raise RuntimeError("call reset() before step()")
        if self.drivers is not None:
            self.drivers.act(run)
        run.set_actions([self.agent], [action], [f"robot_{self.agent}"])
        run.advance()
        obs = run.observe()[self.agent]
        info: dict = {}
        reward = float(self.reward_fn(run.world, self.agent, info))
        gone = run.gone(self.agent) if self.terminated_fn is None else self.terminated_fn(run.world, self.agent)
        truncated = run.over(self.max_ticks) and not gone
        return obs, reward, bool(gone), bool(truncated), info

    def render(self) -> np.ndarray | None:
        """A top-down picture of the arena as an (h, w, 3) uint8 array."""
        if self.render_mode != "rgb_array" or self.run is None:
            return None
        return self.canvas.frame(self.run.world)


def make(scenario: str | ArenaScenario, *, agent: int = 0, reward: Reward | None = None,
         terminated: Terminated | None = None, max_ticks: int | None = None, seed: int | None = None,
         render_mode: str | None = None, **overrides: Any) -> ArenaGymEnv:  # fmt: skip
    """Robot `agent` of the scenario (as swarm.envs.parallel_env takes it) as a Gymnasium env."""
    s = arena_scenario(scenario, max_ticks, **overrides)
    return ArenaGymEnv(s, agent=agent, reward=reward, terminated=terminated, max_ticks=max_ticks, seed=seed,
                       render_mode=render_mode)  # fmt: skip
