"""Wheel odometry: distance and turn since the last control period."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from world_server.arena.face.sensors.base import Reading, Sensor

NOISE = 5  # noise stream: the relative errors of the distance and the turn
BIAS = 15  # noise stream, drawn once per robot and run: the distance's and the turn's bias


@dataclass(frozen=True)
class Odometry(Sensor):
    """Distance and turn since the last control period, each off by a uniform
    relative error within `error` (the BG paper's +-5% of the distance), drawn
    afresh every tick, and by a bias within `bias`, drawn once per robot and
    run (a wheel a little larger than its specification): the fresh errors
    average out along a path, the bias adds up, so the odometric position
    drifts.  The bias is 0 unless a scenario sets it."""

    name = "odometry"
    rank = 4
    streams = (NOISE, BIAS)

    error: float = 0.05
    bias: float = 0.0

    def read(self, r: Reading) -> dict[str, np.ndarray]:
        factor = r.noise.factor(self.name)
        err = r.uniform(NOISE, 2) * self.error * factor
        if self.bias and r.per_run is not None:
            err = err + r.per_run(BIAS, 2) * self.bias * factor
        return {"odometry": r.state.motion[r.robots] * (1.0 + err)}

    def readings(self) -> dict[str, tuple[tuple[int, ...], str]]:
        return {"odometry": ((2,), "<f8")}


SENSOR = Odometry
