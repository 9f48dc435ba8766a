"""The robots no learner drives, each driven by its scenario controller the way the in-process
engine (swarm.engines.arena) drives it: reset with the run's seed and its params, stepped on its
perception each tick, its broadcasts and shared publications handed on."""

from __future__ import annotations

from agents.controllers.arena import StepGuard, broadcasts, deliver, make_controller, publications
from swarm.envs.run import ArenaRun
from world_server.arena.scenario import controller_params


class Drivers:
    """Controllers of `robots` (global ids) for one episode of `run`; one that raises holds its robot still."""

    def __init__(self, run: ArenaRun, robots: list[int]):
        s = run.scenario
        names = [g.controller for g in s.groups for _ in range(g.count)]
        self.robots = list(robots)
        self.names = [names[a] for a in self.robots]
        self.guard = StepGuard("idle")
        self.controllers = []
        for a, name in zip(self.robots, self.names, strict=True):
            c = make_controller(name)
            self.guard.reset(c, s.seed, a, controller_params(s, a), name)
            self.controllers.append(c)

    def act(self, run: ArenaRun) -> None:
        """Their actions for this tick into `run.actions`, from the perceptions of `run.observe()`."""
        tick = run.world.tick
        for a, name, c in zip(self.robots, self.names, self.controllers, strict=True):
            run.actions[a] = self.guard.action(c, run.perception[a], a, name, tick)
        working = self.guard.working(zip(self.controllers, self.robots, strict=True))
        run.world.broadcast(broadcasts(*working))
        shared = publications(*working)
        if shared:
            deliver(*working, shared)
