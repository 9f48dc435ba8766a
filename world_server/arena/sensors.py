"""Sensor suites: the rays a robot model casts and what its sensors make of them.

This is the simulator side of the sensors (ARGoS's split): which rays leave a robot, and how
ranges and hit colours become readings with noise.  The controller gets only the perception dict.
Each sensor says its own part (world_server/arena/face/sensors/: one module each); a suite
gathers its model's sensors in their registry order, lays their rays out in one block each,
hands each sensor its block of the compiled ray pass (world_server.arena.raycast casts all rays
of all robots together) and the world's state, and draws their noise.  Every noise draw comes from
swarm.core.rng keyed by (seed, agent, tick, stream), so a reading never depends on who else is in
the run.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import partial

import numpy as np

from swarm.core.rng import fill_normal, fill_uniform
from world_server.arena import raycast
from world_server.arena.face.robots import RobotModel
from world_server.arena.face.sensors import Reading, Sensor
from world_server.arena.noise import fill_normal_parallel
from world_server.arena.raycast import MARK, SOLID

NOISE_LEVELS = ("none", "low", "high")
LEVEL_SCALE = {"none": 0.0, "low": 1.0, "high": 2.0}  # on every sensor's specified error
PER_RUN = -1  # the tick that keys a run's per-robot draws (a sensor's bias): ticks count from 0


@dataclass(frozen=True)
class Noise:
    """How noisy a run is: a level (the DFT paper's none / low / high) and, per
    sensor, a factor on that sensor's specified error."""

    level: str = "low"
    scale: tuple[tuple[str, float], ...] = ()

    def scale_of(self, sensor: str) -> float:
        """The [noise] table's factor for this sensor (1 when it names none)."""
        return dict(self.scale).get(sensor, 1.0)

    def level_scale(self) -> float:
        return LEVEL_SCALE[self.level]

    def factor(self, sensor: str) -> float:
        """What a sensor's specified error is multiplied by in this run."""
        return self.scale_of(sensor) * self.level_scale()


class Suite:
    """The sensors of one robot model for a group of robots (global ids `robots`)."""

    def __init__(self, model: RobotModel, robots: np.ndarray, noise: Noise, seed: int):
        self.model, self.robots, self.noise, self.seed = model, np.asarray(robots, np.int64), noise, seed
        self.sensors = model.sensors.specs
        bearings, ranges, offsets, masks = [], [], [], []
        self.blocks: dict[str, slice] = {}  # each casting sensor's rays
        self.casting: list[Sensor] = []
        self.colours = False  # whether a sensor reads the colours its rays hit
        for sensor in self.sensors:
            block = sensor.rays(model)
            if block is None:
                continue
            start, k = sum(len(x) for x in bearings), len(block.bearings)
            bearings.append(np.asarray(block.bearings, np.float64))
            ranges.append(np.full(k, block.range + block.offsets))
            offsets.append(np.full(k, block.offsets))
            masks.append(np.full(k, SOLID | MARK if block.marks else SOLID, np.uint8))
            self.blocks[sensor.name] = slice(start, start + k)
            self.casting.append(sensor)
            self.colours |= block.colours
        self.bearings = np.concatenate(bearings) if bearings else np.zeros(0)
        self.ranges = np.concatenate(ranges) if ranges else np.zeros(0)
        self.offsets = np.concatenate(offsets) if offsets else np.zeros(0)
        self.masks = np.concatenate(masks) if masks else np.zeros(0, np.uint8)
        self.per_robot = len(self.bearings)
        n = len(self.robots)
        bearing = np.tile(self.bearings, n)  # the group's rays, robot-major, without noise
        self._fixed = (np.repeat(self.robots, self.per_robot), bearing, np.tile(self.ranges, n), np.cos(bearing),
                       np.sin(bearing), np.tile(self.masks, n))  # fmt: skip

    def reading(self, tick: int, state=None) -> Reading:
        """What the sensors read at this tick, before the rays' results: the robots, the noise, the draws."""
        return Reading(self.robots, tick, self.noise, partial(self._uniform, tick=tick),
                       partial(self._normal, tick=tick), state,
                       per_run=partial(self._uniform, tick=PER_RUN))  # fmt: skip

    # ------------------------------------------------------------------ rays

    def rays(self, tick: int) -> tuple[np.ndarray, ...]:
        """(robot, bearing, range, cos, sin of bearing, layer mask) of every ray
        of the group, robot-major (cameras see marks, range sensors only
        solids).  A sensor's bearing noise turns its block (the sonar turns
        each cone as a whole); the other bearings are fixed, so their cosines
        are computed once."""
        r = self.reading(tick)
        turns = [(self.blocks[s.name], t) for s in self.casting if (t := s.turn(r)) is not None]
        if not turns:
            return self._fixed
        n = len(self.robots)
        robot, bearing, ranges, c, s, masks = self._fixed
        turned = bearing.reshape(n, self.per_robot).copy()
        b = np.zeros((n, self.per_robot), np.bool_)
        for block, turn in turns:
            turned[:, block] += turn
            b[:, block] = True
        turned, b = turned.ravel(), b.ravel()
        c, s = c.copy(), s.copy()
        c[b], s[b] = np.cos(turned[b]), np.sin(turned[b])
        return robot, turned, ranges, c, s, masks

    def _uniform(self, stream: int, k: int, tick: int) -> np.ndarray:
        out = np.empty((len(self.robots), k))
        fill_uniform(np.int64(self.seed), self.robots, np.int64(tick), np.int64(stream), out)
        return out

    def _normal(self, stream: int, k: int, tick: int) -> np.ndarray:
        out = np.empty((len(self.robots), k))
        parallel = raycast.parallel(out.size, raycast.PARALLEL_NORMALS)
        fill = fill_normal_parallel if parallel else fill_normal  # the same numbers either way
        fill(np.int64(self.seed), self.robots, np.int64(tick), np.int64(stream), out)
        return out

    # --------------------------------------------------------------- reading

    def read(self, ranges: np.ndarray, rgb: np.ndarray | None, what: np.ndarray, state,
             tick: int) -> dict[str, np.ndarray]:  # fmt: skip
        """Readings of every robot of the group, sensor by sensor in the registry's order.
        `ranges`, `rgb`, `what` are this group's rays (n, per_robot[, 3]); `state` is the world
        (poses, motion, contacts, zones) indexed by global robot id."""
        if self.offsets.any():  # (x - 0.0 is x: a suite whose rays start at the centre skips the copy)
            ranges = ranges - self.offsets[None, :]
        base, out = self.reading(tick, state), {}
        for sensor in self.sensors:
            r = base
            if (b := self.blocks.get(sensor.name)) is not None:
                r = replace(base, ranges=ranges[:, b], what=what[:, b], rgb=None if rgb is None else rgb[:, b])
            out.update(sensor.read(r))
        if getattr(state, "metabolism", None) is not None:  # internal sensors: E and Ep
            out["metabolism"] = state.metabolism.levels(self.robots)
        return out
