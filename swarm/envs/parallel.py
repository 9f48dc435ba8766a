"""Every robot of an arena scenario as an agent of a PettingZoo ParallelEnv."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np
from pettingzoo.utils.env import ParallelEnv

from swarm.envs.render import Canvas
from swarm.envs.run import ArenaRun, agent_boxes, rows
from swarm.envs.source import arena_scenario
from world_server.arena.scenario import ArenaScenario
from world_server.arena.world import ArenaWorld

Reward = Callable[[ArenaWorld, int, dict], float]
Terminated = Callable[[ArenaWorld, int], bool]


def no_reward(world: ArenaWorld, agent: int, info: dict) -> float:
    """The default reward: none (a task brings its own)."""
    return 0.0


class ArenaParallelEnv(ParallelEnv):
    """Agents "robot_0".."robot_{n-1}", one per robot in the scenario's group order.  An agent that
    terminates (`terminated(world, a)`, by default: its robot finished or left the world) or is
    truncated (the episode's `max_ticks`) leaves `agents` after that step; its robot holds still."""

    metadata: ClassVar[dict[str, Any]] = {
        "name": "swarm_arena_v0",
        "render_modes": ["rgb_array"],
        "is_parallelizable": True,
    }

    def __init__(self, scenario: ArenaScenario, *, reward: Reward | None = None,
                 terminated: Terminated | None = None, max_ticks: int | None = None, seed: int | None = None,
                 render_mode: str | None = None):  # fmt: skip
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode: expected None or 'rgb_array', got {render_mode!r}")
        self.scenario = scenario
        self.reward_fn = reward or no_reward
        self.terminated_fn = terminated
        self.max_ticks = scenario.max_ticks if max_ticks is None else max_ticks
        self.render_mode = render_mode
        self.possible_agents = [f"robot_{a}" for a in range(scenario.agents)]
        self.index = {name: a for a, name in enumerate(self.possible_agents)}
        obs, act = agent_boxes(scenario)
        self.boxes = obs
        self.observation_spaces = dict(zip(self.possible_agents, obs, strict=True))
        self.action_spaces = dict(zip(self.possible_agents, act, strict=True))
        self.rng = np.random.default_rng(scenario.seed if seed is None else seed)
        self.first_seed = scenario.seed if seed is None else seed
        self.agents: list[str] = []
        self.live_index: dict[str, int] = {}
        self.run: ArenaRun | None = None
        self.canvas = Canvas()

    def observation_space(self, agent: str):
        return self.observation_spaces[agent]

    def action_space(self, agent: str):
        return self.action_spaces[agent]

    def next_seed(self, seed: int | None) -> int:
        """The world's seed: `seed` (which also reseeds the draws of later resets), else the env's
        seed on the first reset and a draw of its generator after."""
        if seed is not None:
            self.rng = np.random.default_rng(seed)
            return int(seed)
        if self.first_seed is not None:
            first, self.first_seed = self.first_seed, None
            return int(first)
        return int(self.rng.integers(2**31 - 1))

    def reset(self, seed: int | None = None, options: dict | None = None) -> tuple[dict, dict]:
        """A fresh world (same seed, same world and observations)."""
        self.run = ArenaRun(self.scenario, self.next_seed(seed), self.boxes)
        self.first_seed = None
        self.agents = list(self.possible_agents)
        self.live_index = dict(self.index)
        seen = self.run.observe()
        return {name: seen[a] for a, name in enumerate(self.agents)}, {name: {} for name in self.agents}

    def step(self, actions: dict[str, Any]) -> tuple[dict, dict, dict, dict, dict]:
        """One tick: the live agents' wheel speeds (a live agent left out holds still this tick)."""
        run = self.live_run()
        live = self.agents
        run.actions[:] = 0.0
        run.set_actions(*rows(actions, self.live_index))
        run.advance()
        seen = run.observe()
        over, world = run.over(self.max_ticks), run.world
        obs, rewards, terms, truncs, infos = {}, {}, {}, {}, {}
        for name in live:
            a = self.index[name]
            obs[name] = seen[a]
            infos[name] = info = {}
            rewards[name] = float(self.reward_fn(world, a, info))
            terms[name] = bool(run.gone(a) if self.terminated_fn is None else self.terminated_fn(world, a))
            truncs[name] = over and not terms[name]
            if terms[name] or truncs[name]:
                run.held[a] = True
        self.agents = [name for name in live if not run.held[self.index[name]]]
        self.live_index = {name: self.index[name] for name in self.agents}
        return obs, rewards, terms, truncs, infos

    def live_run(self) -> ArenaRun:
        if self.run is None:
            raise RuntimeError("call reset() before step()")
        return self.run

    def render(self) -> np.ndarray | None:
        """A top-down picture of the arena (walls and robots) as an (h, w, 3) uint8 array."""
        if self.render_mode != "rgb_array" or self.run is None:
            return None
        return self.canvas.frame(self.run.world)

    def close(self) -> None:
        self.run = None

    def state(self) -> np.ndarray:
        """The global state: every robot's true pose (x, y, heading)."""
        return self.live_run().world.pose.copy()


def parallel_env(scenario: str | ArenaScenario, *, reward: Reward | None = None, terminated: Terminated | None = None,
                 max_ticks: int | None = None, seed: int | None = None, render_mode: str | None = None,
                 **overrides: Any) -> ArenaParallelEnv:  # fmt: skip
    """The scenario (a bundled name, a file or an ArenaScenario; `overrides` as
    ArenaScenario.with_overrides: agents, noise, controller, ...) as a ParallelEnv.  `reward(world,
    a, info) -> float` and `terminated(world, a) -> bool` see the world after each tick; `max_ticks`
    defaults to the scenario's; `seed` is the first reset's world seed (default the scenario's)."""
    s = arena_scenario(scenario, max_ticks, **overrides)
    return ArenaParallelEnv(s, reward=reward, terminated=terminated, max_ticks=max_ticks, seed=seed,
                            render_mode=render_mode)  # fmt: skip
