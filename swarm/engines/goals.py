"""What an arena run asks of its robots, kept above the world, and the run's summary.

Each robot may have a goal, or a route whose last waypoint is its goal.  On
ground truth, after every tick: the waypoint it drives to next, the tick it
first reached its goal, how long it has dwelt there; a robot that has dwelt
`goal_dwell` ticks is finished (the world holds it still from then on), and the
run ends when every robot with a goal in the world has finished.  L_o, the A*
optimum its path is compared with, is worked out once per robot, from where it
came in.  The in-process engine (swarm.engines.arena) and the world process
(lent by swarm.world_process) keep them the same way, so both summaries agree.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from agents.controllers.navigation.astar import Planner
from world_server.arena.scenario import ArenaScenario
from world_server.arena.world import ArenaWorld

OPTIMUM_CELL, OPTIMUM_CLEARANCE = 0.01, 0.04  # the DFT paper's A* optimum
MAX_OPTIMUM_CELLS = 4_000_000  # coarser cells on large floors (docs/arena.md)


@functools.lru_cache(maxsize=8)
def optimum_planner(size: tuple[float, float], walls: tuple) -> Planner:
    """The A* planner of L_o on this floor (shared by the runs of one scenario)."""
    cell = max(OPTIMUM_CELL, math.sqrt(size[0] * size[1] / MAX_OPTIMUM_CELLS))
    rects = np.array([w.coords for w in walls if w.shape == "rect"], np.float64).reshape(-1, 4)
    segments = np.array([w.coords for w in walls if w.shape == "segment"], np.float64).reshape(-1, 4)
    return Planner(size, rects, segments, cell, OPTIMUM_CLEARANCE)


def optimal_lengths(s: ArenaScenario, starts: np.ndarray, which=None) -> list[float | None]:
    """L_o per robot: A* (1 cm, 4 cm clearance) from its true start through its
    route or to its goal; inf when there is none or no path keeps the clearance.
    Only robots in `which` (default all); None for the others."""
    planner = optimum_planner(s.size, s.walls)
    routes = [s.routes[g.route] if g.route else None for g in s.groups for _ in range(g.count)]
    which = set(range(len(starts))) if which is None else set(which)
    out: list[float | None] = []
    for a, goal in enumerate(s.goals()):
        if a not in which:
            out.append(None)
            continue
        targets = routes[a] or ([goal] if goal is not None else [])
        here, total = (float(starts[a, 0]), float(starts[a, 1])), 0.0 if targets else math.inf
        for t in targets:
            total += planner.plan(here, tuple(t))[0]
            here = tuple(t)
        out.append(total)
    return out


class ArenaGoals:
    """Every robot's goal or route and its progress on them, for one run of a scenario."""

    STATE = ("reached_tick", "dwell", "waypoint")  # saved with the world's state (and "optimum")

    def __init__(self, scenario: ArenaScenario):
        s = self.scenario = scenario
        goals = s.goals()
        n = len(goals)
        self.goal = np.full((n, 2), np.nan)
        self.route: list[np.ndarray | None] = [None] * n
        for a, goal in enumerate(goals):
            if goal is not None:
                self.goal[a] = goal
        agent = 0
        for g in s.groups:
            for _ in range(g.count):
                if g.route is not None:
                    self.route[agent] = np.array(s.routes[g.route], np.float64).reshape(-1, 2)
                    self.goal[agent] = self.route[agent][-1]
                agent += 1
        self.has_goal = ~np.isnan(self.goal[:, 0])
        self.waypoint = np.zeros(n, np.int64)  # next route waypoint per robot
        self.reached_tick = np.full(n, -1, np.int64)
        self.dwell = np.zeros(n, np.int64)
        self.optimum: list[float | None] = [None] * n  # L_o per robot, once it is in the world

    def track(self, world: ArenaWorld) -> None:
        """After a tick: waypoints passed, goals reached, dwell counted; the robots that have dwelt
        long enough are finished."""
        s = self.scenario
        finished = []
        for a in np.flatnonzero(self.has_goal & ~world.finished & world.in_world):
            x, y = world.pose[a, :2]
            route = self.route[a]
            if route is not None and self.waypoint[a] < len(route) - 1:
                wx, wy = route[self.waypoint[a]]
                if math.hypot(x - wx, y - wy) < s.goal_radius:
                    self.waypoint[a] += 1
                continue
            if math.hypot(x - self.goal[a, 0], y - self.goal[a, 1]) < s.goal_radius:
                if self.reached_tick[a] < 0:
                    self.reached_tick[a] = world.tick
                self.dwell[a] += 1
                if self.dwell[a] >= s.goal_dwell:
                    finished.append(a)
        if finished:
            world.finish(finished)

    def done(self, world: ArenaWorld) -> bool:
        """Every robot with a goal in the world has finished (a run with a metabolism ends by its rule alone)."""
        if world.metabolism is not None:
            return False
        goals = self.has_goal & world.in_world
        return bool(goals.any()) and bool(world.finished[goals].all())

    def fill_optimum(self, world: ArenaWorld) -> None:
        """L_o (A*) for every robot in the world that has none yet: once per robot,
        its start does not change once it is in."""
        missing = [a for a in np.flatnonzero(world.in_world).tolist() if self.optimum[a] is None]
        if missing:
            for a, lo in enumerate(optimal_lengths(self.scenario, world.start_pose, missing)):
                if lo is not None:
                    self.optimum[a] = lo

    def snapshot(self) -> dict[str, np.ndarray]:
        """What a resumed run continues from (arrays only, beside the world's snapshot)."""
        out = {k: np.array(getattr(self, k)) for k in self.STATE}
        out["optimum"] = np.array([np.nan if v is None else v for v in self.optimum])
        return out

    def restore(self, state: dict[str, np.ndarray]) -> None:
        for k in self.STATE:
            getattr(self, k)[...] = state[k]
        self.optimum = [None if np.isnan(v) else float(v) for v in state["optimum"]]

    # -------------------------------------------------------------- summary

    def robot_rows(self, world: ArenaWorld) -> list[dict[str, Any]]:
        """One row per robot that has been in the world (L_o as far as it is filled in)."""
        s = self.scenario
        out = []
        controllers = [g.controller for g in s.groups for _ in range(g.count)]
        for a in np.flatnonzero(world.in_world).tolist():
            # reached: it dwelt at its goal (a robot pushed off it afterwards keeps that), or ends within the radius
            near = math.hypot(*(world.pose[a, :2] - self.goal[a])) < s.goal_radius
            reached = bool(self.has_goal[a]) and (bool(world.finished[a]) or near)
            lo = math.inf if self.optimum[a] is None else self.optimum[a]
            lp = float(world.path_length[a])
            out.append({
                "agent": a, "controller": controllers[a],
                "start": [round(float(v), 4) for v in world.start_pose[a]],
                "goal": None if not self.has_goal[a] else [round(float(v), 4) for v in self.goal[a]],
                "reached": reached,
                "ticks_to_goal": int(self.reached_tick[a]) if self.reached_tick[a] >= 0 else None,
                "path_length": round(lp, 4),
                "optimal_length": None if not math.isfinite(lo) else round(lo, 4),
                "path_ratio": round(lp / lo, 4) if reached and math.isfinite(lo) and lo > 0 else None,
                "collisions": int(world.bodies.collisions[a]),
                "distance": round(float(world.bodies.distance[a]), 4),
                "blocked_seconds": round(float(world.bodies.blocked_seconds[a]), 3),
                "pose": [round(float(v), 5) for v in world.pose[a]],
                **({} if world.metabolism is None else world.metabolism.summary(a, s.control_period, world.tick)),
            })  # fmt: skip
        return out

    def summary(self, world: ArenaWorld, wall_seconds: float, runtime: str) -> dict[str, Any]:
        """What the run did, robot by robot: the same keys in every runtime (each adds its own on top)."""
        self.fill_optimum(world)
        s = self.scenario
        robots = self.robot_rows(world)
        goals = [r for r in robots if r["goal"] is not None]
        ratios = [r["path_ratio"] for r in robots if r["path_ratio"] is not None]
        return {
            "scenario": s.name,
            "kind": "arena",
            "controller": s.controller,
            "agents": len(robots),
            "seed": s.seed,
            "noise": s.noise.level,
            "runtime": runtime,
            "ticks": world.tick,
            "iterations": world.tick,
            # with goals: all reached; without (explorers): the run went its full length; survival: its rule ended it
            "finished": all(r["reached"] for r in goals)
            if goals
            else (world.tick >= s.max_ticks or (world.metabolism is not None and world.metabolism.done())),
            "reached": sum(r["reached"] for r in goals),
            "with_goal": len(goals),
            "sim_seconds": round(world.tick * s.control_period, 3),
            "wall_seconds": round(wall_seconds, 4),
            "ticks_per_second": round(world.tick / wall_seconds, 1) if wall_seconds else None,
            "mean_path_ratio": round(float(np.mean(ratios)), 4) if ratios else None,
            "collisions": int(world.bodies.collisions.sum()),
            "rejected_actions": sum(world.rejected.values()),
            "rejected": dict(world.rejected),
            "robots": robots,
        }
