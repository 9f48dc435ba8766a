"""The in-process arena engine: the world and every robot's controller in one
process, in the lock-step tick of world_server.arena.world (all perceive, all
decide, the world integrates one control period)."""

from __future__ import annotations

import functools
import math
import time
from typing import Any

import numpy as np

from agents.controllers.arena import as_action, deliver, make_controller, publications
from agents.controllers.navigation.astar import Planner
from swarm.engines.stepper import step_world
from world_server.arena.scenario import ArenaScenario, controller_params
from world_server.arena.summary import arena_summary
from world_server.arena.world import ArenaWorld
from world_server.history import ShareLog

OPTIMUM_CELL, OPTIMUM_CLEARANCE = 0.01, 0.04  # the DFT paper's A* optimum
MAX_OPTIMUM_CELLS = 4_000_000  # coarser cells on large floors (docs/arena.md)


@functools.lru_cache(maxsize=8)
def _planner(size: tuple[float, float], walls: tuple) -> Planner:
    cell = max(OPTIMUM_CELL, math.sqrt(size[0] * size[1] / MAX_OPTIMUM_CELLS))
    rects = np.array([w.coords for w in walls if w.shape == "rect"], np.float64).reshape(-1, 4)
    segments = np.array([w.coords for w in walls if w.shape == "segment"], np.float64).reshape(-1, 4)
    return Planner(size, rects, segments, cell, OPTIMUM_CLEARANCE)


def optimal_lengths(s: ArenaScenario, starts: np.ndarray, which=None) -> list[float | None]:
    """L_o per robot: A* (1 cm, 4 cm clearance) from its true start through its
    route or to its goal; inf when there is none or no path keeps the clearance.
    Only robots in `which` (default all); None for the others."""
    planner = _planner(s.size, s.walls)
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


def fill_optimum(world: ArenaWorld) -> None:
    """L_o (A*) for every robot in the world that has none yet: once per robot,
    its start does not change once it is in."""
    missing = [a for a in np.flatnonzero(world.in_world).tolist() if world.optimum[a] is None]
    if missing:
        for a, lo in enumerate(optimal_lengths(world.scenario, world.start_pose, missing)):
            if lo is not None:
                world.optimum[a] = lo


class ArenaEngine:
    def __init__(self, scenario: ArenaScenario):
        self.scenario = scenario
        self.world = ArenaWorld(scenario)
        self.controllers = []
        for a, group in enumerate(g for g in scenario.groups for _ in range(g.count)):
            c = make_controller(group.controller)
            c.reset(scenario.seed, a, controller_params(scenario, a))
            self.controllers.append(c)
        self.wall_seconds = 0.0
        self.actions = np.zeros((self.world.n, 3))  # wheel speeds and an act (world_server.arena.world.ACTION_WIDTH)
        self.agent_ids = list(range(len(self.controllers)))
        self.shares = ShareLog()
        self.refused_shared = 0

    @property
    def tick(self) -> int:
        return self.world.tick

    def step(self, n: int = 1, recorder=None) -> int:
        """Up to n ticks (fewer once the run is done); returns ticks run.  A
        `recorder` (swarm.recording.arena.ArenaRecorder) takes every tick."""
        w = self.world
        started = time.perf_counter()
        last = [started]

        def decide(perceptions, tick: int) -> np.ndarray:
            for a, (c, p) in enumerate(zip(self.controllers, perceptions, strict=True)):
                self.actions[a] = as_action(c.step(p))
            shared = publications(self.controllers, self.agent_ids)
            if shared:  # what each wrote this tick, every other robot of its share reads before the next
                self.shares.add(tick, shared)
                self.refused_shared += deliver(self.controllers, self.agent_ids, shared)
            return self.actions

        def record() -> None:
            now = time.perf_counter()
            recorder.capture(w.tick - 1, tick_ms=(now - last[0]) * 1000, rejected=sum(w.rejected.values()))
            last[0] = now

        ran = step_world(w, decide, n, record if recorder is not None else None)
        self.wall_seconds += time.perf_counter() - started
        return ran

    def run(self, progress: bool = False, chunk: int = 50, recorder=None) -> dict[str, Any]:
        bar = None
        if progress:
            from tqdm import tqdm

            bar = tqdm(total=self.scenario.max_ticks, unit="tick", desc=self.scenario.name, leave=False)
        try:
            while not self.world.done():
                ran = self.step(chunk, recorder)
                if bar is not None:
                    bar.update(ran)
        finally:
            if bar is not None:
                bar.close()
        return self.summary()

    def summary(self) -> dict[str, Any]:
        fill_optimum(self.world)
        out = arena_summary(self.world, self.wall_seconds, "in-process")
        for robot, c in zip(out["robots"], self.controllers, strict=True):
            if hasattr(c, "summary"):  # what a controller learned (a map), beside what its body did
                robot.update(c.summary())
            if (shared := self.shares.of(robot["agent"])) is not None:
                robot["shared"] = shared
        out["rejected_shared"] = self.refused_shared
        return out


def warm_up(scenario: ArenaScenario, engine: bool = False) -> None:
    """Compile, or load from the cache, what an arena run needs (world_server.WORLD_KINDS): the ray
    pass, the drive and A* (arena agents plan with it), by one tick of this engine."""
    ArenaEngine(scenario).step(1)
