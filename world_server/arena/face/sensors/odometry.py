"""Wheel odometry: distance and turn since the last control period."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from world_server.arena.face.sensors.base import Reading, Sensor

NOISE = 5  # noise stream: the relative errors of the distance and the turn


@dataclass(frozen=True)
class Odometry(Sensor):
    """Distance and turn since the last control period, each off by a uniform
    relative error within `error` (the BG paper's +-5% of the distance)."""

    name = "odometry"
    rank = 4
    streams = (NOISE,)

    error: float = 0.05

    def read(self, r: Reading) -> dict[str, np.ndarray]:
        err = r.uniform(NOISE, 2) * self.error * r.noise.factor(self.name)
        return {"odometry": r.state.motion[r.robots] * (1.0 + err)}

    def readings(self) -> dict[str, tuple[tuple[int, ...], str]]:
        return {"odometry": ((2,), "<f8")}


SENSOR = Odometry
