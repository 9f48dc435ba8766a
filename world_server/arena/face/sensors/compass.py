"""A compass: the robot's heading."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from world_server.arena.face.sensors.base import DEG, Reading, Sensor

NOISE = 6  # noise stream: the heading's error


@dataclass(frozen=True)
class Compass(Sensor):
    """The heading in [0, 2 pi), off by a uniform error within +-`error`."""

    name = "compass"
    rank = 5
    streams = (NOISE,)

    error: float = 10 * DEG  # uniform within +-error

    def read(self, r: Reading) -> dict[str, np.ndarray]:
        e = r.uniform(NOISE, 1)[:, 0] * self.error * r.noise.factor(self.name)
        return {"compass": (r.state.pose[r.robots, 2] + e) % (2 * math.pi)}

    def readings(self) -> dict[str, tuple[tuple[int, ...], str]]:
        return {"compass": ((), "<f8")}


SENSOR = Compass
