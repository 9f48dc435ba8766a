"""How crowded a robot is: the number of other robots within `radius`, a sensor of this package
(entry point group `swarm.sensors`), not of swarm.

A robot counts every other robot in the arena whose centre is within `radius` metres of its own,
through walls (a crude proximity board: it hears the others' beacons, it does not see them).  The
count errs by a normal error of std `miss` times the square root of the count (each robot counted
errs on its own), rounded, never below 0, drawn from its own noise stream; the run's noise level
and a [noise] table's `neighbour_count` scale it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from world_server.arena.face.sensors import Reading, Sensor

NOISE = 101  # noise stream: the count's error (swarm's own sensors draw from streams under 100)


@dataclass(frozen=True)
class NeighbourCount(Sensor):
    """The number of other robots within `radius` metres (centre to centre), with a normal error of
    std `miss` times the square root of the count, rounded."""

    name = "neighbour_count"
    rank = 100  # after swarm's own sensors: its reading comes last in a perception
    streams = (NOISE,)

    radius: float = 0.3  # m: about four e-puck diameters
    miss: float = 0.1  # std of the count's error, per robot counted

    def check(self, model) -> None:
        if not (self.radius > 0 and math.isfinite(self.radius)):
            raise ValueError(f"radius: expected a positive distance in metres, got {self.radius}")
        if not (self.miss >= 0 and math.isfinite(self.miss)):
            raise ValueError(f"miss: expected a finite std of at least 0, got {self.miss}")

    def read(self, r: Reading) -> dict[str, np.ndarray]:
        state = r.state
        live = np.asarray(state.in_world & state.present)
        xy = state.pose[:, :2]
        d = np.hypot(*(xy[None, :, :] - xy[r.robots, None, :]).transpose(2, 0, 1))
        near = (d <= self.radius) & live[None, :]
        near[np.arange(len(r.robots)), r.robots] = False  # not itself
        count = near.sum(axis=1).astype(np.float64)
        factor = r.noise.factor(self.name)
        if factor and self.miss:
            count = count + r.normal(NOISE, 1)[:, 0] * self.miss * factor * np.sqrt(count)
        return {"neighbour_count": np.maximum(np.rint(count), 0).astype(np.int64)}

    def readings(self) -> dict[str, tuple[tuple[int, ...], str]]:
        return {"neighbour_count": ((), "<i8")}

    @classmethod
    def tells(cls, spec: Sensor | None, model) -> dict[str, Any]:
        assert spec is None or isinstance(spec, NeighbourCount)
        return {"neighbour_radius": None if spec is None else spec.radius}
