"""A compass: the robot's heading."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from world_server.arena.face.sensors.base import DEG, Reading, Sensor

NOISE = 6  # noise stream: the heading's error
BIAS = 16  # noise stream, drawn once per robot and run: the heading's bias


@dataclass(frozen=True)
class Compass(Sensor):
    """The heading in [0, 2 pi), off by a uniform error within +-`error` drawn
    afresh every tick, and by a bias within +-`bias` drawn once per robot and
    run (a compass mounted a little askew, or a magnetic field a little off):
    the fresh errors average out, the bias turns every odometric step.  The
    bias is 0 unless a scenario sets it."""

    name = "compass"
    rank = 5
    streams = (NOISE, BIAS)

    error: float = 10 * DEG  # uniform within +-error
    bias: float = 0.0  # uniform within +-bias, once per robot and run

    def read(self, r: Reading) -> dict[str, np.ndarray]:
        e = r.uniform(NOISE, 1)[:, 0] * self.error * r.noise.factor(self.name)
        if self.bias and r.per_run is not None:
            e = e + r.per_run(BIAS, 1)[:, 0] * self.bias * r.noise.factor(self.name)
        return {"compass": (r.state.pose[r.robots, 2] + e) % (2 * math.pi)}

    def readings(self) -> dict[str, tuple[tuple[int, ...], str]]:
        return {"compass": ((), "<f8")}


SENSOR = Compass
