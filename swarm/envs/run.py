"""One episode of an arena env: the world, the run's goals, the learners' actions turned into
the world's action rows, and the perceptions turned into observations matching the spaces.

The tick is the in-process engine's (swarm.engines.arena): all perceive the start-of-tick world,
the world resolves one control period from every robot's wheel speeds, then the goals are tracked
(a robot that dwelt at its goal is finished and held still by the world)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from gymnasium import spaces

from swarm.engines.goals import ArenaGoals
from world_server.arena.metabolism import ACTS
from world_server.arena.scenario import ArenaScenario
from world_server.arena.wheels import ACTION_WIDTH
from world_server.arena.world import ArenaWorld


class ArenaRun:
    """A fresh world of `scenario` under `seed`; `boxes[a]` is robot a's observation space."""

    def __init__(self, scenario: ArenaScenario, seed: int, boxes: list[spaces.Dict]):
        self.scenario = scenario.with_overrides(seed=seed)
        self.world = ArenaWorld(self.scenario)
        self.goals = ArenaGoals(self.scenario)
        self.actions = np.zeros((self.world.n, ACTION_WIDTH))
        self.held = np.zeros(self.world.n, np.bool_)  # done agents: their robots hold still from then on
        # per group: (its robots, the dtype of each reading its space declares)
        self.casts = [(suite.robots.tolist(), {k: box.dtype for k, box in boxes[int(suite.robots[0])].items()})
                      for suite in self.world.suites]  # fmt: skip
        self.perception: list[dict[str, np.ndarray]] = []

    def observe(self) -> list[dict[str, np.ndarray]]:
        """Every robot's observation of the start-of-tick world: one copy per reading per group, in
        the declared dtype, and a view of its row per robot (a scalar reading is a 0-d array)."""
        out: list[dict[str, np.ndarray]] = [{}] * self.world.n
        for (robots, dtypes), batch in zip(self.casts, self.world.perceive_groups(), strict=True):
            arrays = [(k, np.array(batch[k], dt)) for k, dt in dtypes.items()]
            for i, a in enumerate(robots):
                out[a] = {k: v[i, ...] for k, v in arrays}
        self.perception = out
        return out

    def set_actions(self, robots: list[int], actions: list, names: list[str]) -> None:
        """These robots' actions for this tick: wheel speeds (one array op for all of them), or a dict
        of the action space's `wheels`, `act` and `broadcast`.  NaN or inf is refused (ValueError, one
        line naming the agent): a learner that answers it has diverged, and holding the robot still
        would hide that; finite speeds beyond the model's limit are clipped to it (a Box policy's
        samples may overshoot its bounds).  An act the world does not know, or a broadcast from a
        robot without a range-and-bearing sensor, is refused likewise."""
        if not robots:
            return
        parts = [self._parts(a, action, name) for a, action, name in zip(robots, actions, names, strict=True)]
        actions = [wheels for wheels, _, _ in parts]
        try:
            wheels = np.asarray(actions, np.float64).reshape(len(robots), 2)
        except ValueError:
            shapes = [np.shape(a) for a in actions]
            k = next((i for i, shape in enumerate(shapes) if shape not in ((2,), (1, 2))), 0)
            raise ValueError(f"{names[k]}: expected 2 wheel speeds, got shape {shapes[k]}") from None
        if not np.isfinite(wheels).all():
            k = int(np.flatnonzero(~np.isfinite(wheels).all(axis=1))[0])
            raise ValueError(f"{names[k]}: wheel speeds must be finite, got {wheels[k].tolist()}")
        limit = self.world.max_wheel[robots][:, None]
        self.actions[robots, :2] = np.clip(wheels, -limit, limit)
        self.actions[robots, 2] = [act for _, act, _ in parts]
        self.world.broadcast([(a, sent) for a, (_, _, sent) in zip(robots, parts, strict=True) if sent is not None])

    def _parts(self, robot: int, action, name: str) -> tuple[object, int, bytes | None]:
        """(wheels, act, broadcast bytes or None) of one robot's action."""
        if not isinstance(action, Mapping):
            return action, 0, None
        if unknown := set(action) - {"wheels", "act", "broadcast"}:
            raise ValueError(f"{name}: unknown action keys {sorted(unknown)}; expected wheels, act, broadcast")
        if "wheels" not in action:
            raise ValueError(f"{name}: an action dict needs its 'wheels'")
        act, sent = action.get("act", 0), action.get("broadcast")
        acts = len(ACTS) if self.world.metabolism is not None else 1
        try:
            whole = np.ndim(act) == 0 and float(act).is_integer()
        except (TypeError, ValueError):  # not a number at all
            whole = False
        if not (whole and 0 <= int(act) < acts):
            raise ValueError(f"{name}: act must be a whole number from 0 to {acts - 1} "
                             f"({', '.join(ACTS[:acts])}), got {act!r}")  # fmt: skip
        if sent is not None:
            if self.world.rab_size[robot] == 0:
                raise ValueError(f"{name}: its robot has no range_and_bearing sensor to broadcast with")
            data = np.asarray(bytearray(sent) if isinstance(sent, bytes | bytearray) else sent)
            bytes_like = data.ndim == 1 and data.dtype.kind in "ui"
            if not (bytes_like and (data.size == 0 or 0 <= data.min() <= data.max() <= 255)):
                raise ValueError(f"{name}: broadcast must be bytes or a 1-D array of 0-255, got {data.dtype} "
                                 f"{data.shape}")  # fmt: skip
            sent = data.astype(np.uint8).tobytes()
        return action["wheels"], int(act), sent

    def advance(self) -> None:
        """One tick from the actions set (held robots' rows zeroed), goals tracked after it."""
        self.actions[self.held] = 0.0
        self.world.apply_all(self.actions)
        self.goals.track(self.world)

    def gone(self, a: int) -> bool:
        """The default end of an agent: its robot finished (reached its goal, or died) or left the world."""
        w = self.world
        return bool(w.finished[a]) or not (w.in_world[a] and w.present[a])

    def over(self, max_ticks: int) -> bool:
        """The episode's time is up: `max_ticks`, or the world's own end (its metabolism's rule)."""
        return self.world.tick >= max_ticks or self.world.done()


def agent_boxes(scenario: ArenaScenario) -> tuple[list[spaces.Dict], list[spaces.Space]]:
    """Every robot's observation and action space, one pair per group shared by its robots."""
    from swarm.envs.spaces import action_space, observation_space

    obs, act = [], []
    for g in scenario.groups:
        metabolism = scenario.metabolism is not None
        o, a = observation_space(g.robot, metabolism), action_space(g.robot, metabolism)
        obs += [o] * g.count
        act += [a] * g.count
    return obs, act


def rows(actions: Mapping[str, object], live: Mapping[str, int]) -> tuple[list[int], list, list[str]]:
    """The robots, actions and agent names of the actions given, refusing an agent that is not live."""
    names = list(actions)
    try:
        robots = [live[name] for name in names]
    except KeyError as exc:
        raise ValueError(f"{exc.args[0]}: not a live agent of this env") from None
    return robots, list(actions.values()), names
