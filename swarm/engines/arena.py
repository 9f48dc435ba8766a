"""The in-process arena engine: the world and every robot's controller in one
process, in the lock-step tick of world_server.arena.world (all perceive, all
decide, the world integrates one control period), with the run's goals
(swarm.engines.goals) tracked after every tick."""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from agents.controllers.arena import StepGuard, broadcasts, deliver, make_controller, publications
from swarm.engines.goals import ArenaGoals
from swarm.engines.stepper import step_world
from world_server.arena.scenario import ArenaScenario, controller_params
from world_server.arena.world import ArenaWorld
from world_server.history import ShareLog


class ArenaEngine:
    def __init__(self, scenario: ArenaScenario, on_error: str = "idle"):
        """`on_error`: what a controller that raises does to the run (agents.controllers.arena.StepGuard):
        "idle" holds its robot still and goes on, "stop" ends the run."""
        self.scenario = scenario
        self.world = ArenaWorld(scenario)
        self.goals = ArenaGoals(scenario)
        self.controllers = []
        self.names = [g.controller for g in scenario.groups for _ in range(g.count)]
        self.guard = StepGuard(on_error)
        for a, group in enumerate(g for g in scenario.groups for _ in range(g.count)):
            c = make_controller(group.controller)
            self.guard.reset(c, scenario.seed, a, controller_params(scenario, a), group.controller)
            self.controllers.append(c)
        self.wall_seconds = 0.0
        self.actions = np.zeros((self.world.n, 3))  # wheel speeds and an act (world_server.arena.world.ACTION_WIDTH)
        self.agent_ids = list(range(len(self.controllers)))
        self.shares = ShareLog()
        self.refused_shared = 0

    @property
    def tick(self) -> int:
        return self.world.tick

    def done(self) -> bool:
        """The world's end, or every robot with a goal has finished."""
        return self.world.done() or self.goals.done(self.world)

    def step(self, n: int = 1, recorder=None) -> int:
        """Up to n ticks (fewer once the run is done); returns ticks run.  A
        `recorder` (swarm.recording.arena.ArenaRecorder) takes every tick."""
        w = self.world
        started = time.perf_counter()
        last = [started]

        def decide(perceptions, tick: int) -> np.ndarray:
            for a, (c, p) in enumerate(zip(self.controllers, perceptions, strict=True)):
                self.actions[a] = self.guard.action(c, p, a, self.names[a], tick)
            working = self.guard.working(zip(self.controllers, self.agent_ids, strict=True))
            w.broadcast(broadcasts(*working))
            shared = publications(*working)
            if shared:  # what each wrote this tick, every other robot of its share reads before the next
                self.shares.add(tick, shared)
                self.refused_shared += deliver(*working, shared)
            return self.actions

        def after() -> None:
            self.goals.track(w)
            if recorder is not None:
                now = time.perf_counter()
                recorder.capture(w.tick - 1, tick_ms=(now - last[0]) * 1000, rejected=sum(w.rejected.values()))
                last[0] = now

        ran = step_world(w, decide, n, after, self.done)
        self.wall_seconds += time.perf_counter() - started
        return ran

    def run(self, progress: bool = False, chunk: int = 50, recorder=None) -> dict[str, Any]:
        bar = None
        if progress:
            from tqdm import tqdm

            bar = tqdm(total=self.scenario.max_ticks, unit="tick", desc=self.scenario.name, leave=False)
        try:
            while not self.done():
                ran = self.step(chunk, recorder)
                if bar is not None:
                    bar.update(ran)
        finally:
            if bar is not None:
                bar.close()
        return self.summary()

    def summary(self) -> dict[str, Any]:
        out = self.goals.summary(self.world, self.wall_seconds, "in-process")
        for robot, c in zip(out["robots"], self.controllers, strict=True):
            if hasattr(c, "summary") and robot["agent"] not in self.guard.failed:  # what it learned (a map)
                robot.update(c.summary())
            if (shared := self.shares.of(robot["agent"])) is not None:
                robot["shared"] = shared
        out["rejected_shared"] = self.refused_shared
        if self.guard.failed:  # only then: a summary of a run without failures is what it always was
            out["controller_failures"] = {str(a): why for a, why in sorted(self.guard.failed.items())}
        return out


def warm_up(scenario: ArenaScenario, engine: bool = False) -> None:
    """Compile, or load from the cache, what an arena run needs (world_server.WORLD_KINDS): the ray
    pass, the drive and A* (arena agents plan with it), by one tick of this engine."""
    ArenaEngine(scenario).step(1)
