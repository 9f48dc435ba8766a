"""The DFT paper's noisy position sensor."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from world_server.arena.face.sensors.base import Reading, Sensor

NOISE = 7  # noise stream: the error per axis
STD = {"none": 0.0, "low": 0.005, "high": 0.020}  # DFT paper, section 4: std per noise level


@dataclass(frozen=True)
class Position(Sensor):
    """Noisy position sensor (the DFT paper's): normal error per axis; the
    scenario's noise level sets its std (none 0, low 5 mm, high 20 mm)."""

    name = "position"
    rank = 6
    streams = (NOISE,)

    std: float | None = None  # None: from the noise level

    def std_at(self, noise) -> float:
        """The std of its error at the run's noise (its level, and a [noise] table's factor)."""
        std = STD[noise.level] if self.std is None else self.std * noise.level_scale()
        return std * noise.scale_of(self.name)

    def read(self, r: Reading) -> dict[str, np.ndarray]:
        return {"position": r.state.pose[r.robots, :2] + r.normal(NOISE, 2) * self.std_at(r.noise)}

    def readings(self) -> dict[str, tuple[tuple[int, ...], str]]:
        return {"position": ((2,), "<f8")}


SENSOR = Position
