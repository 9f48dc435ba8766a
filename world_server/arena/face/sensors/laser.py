"""A laser range scanner (the scout's: Tapus et al. 2006 used two back to back)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from world_server.arena.face.sensors.base import Rays, Reading, Sensor

NOISE = 4  # noise stream: each beam's range error


@dataclass(frozen=True)
class Laser(Sensor):
    """`beams` ranges spread over `fov` (a full turn: from the heading counter-clockwise; less:
    centred on the heading), each with a normal error of std `noise`; beyond range reads the range."""

    name = "laser"
    rank = 3
    streams = (NOISE,)

    beams: int = 64
    fov: float = 2 * math.pi
    range: float = 8.0
    noise: float = 0.01  # std, metres

    def rays(self, model) -> Rays:
        full = self.fov >= 2 * math.pi - 1e-9
        bearings = (np.arange(self.beams) / self.beams * self.fov if full
                    else np.linspace(-self.fov / 2, self.fov / 2, self.beams))  # fmt: skip
        return Rays(bearings, self.range)

    def read(self, r: Reading) -> dict[str, np.ndarray]:
        assert r.ranges is not None
        from world_server.arena.noise import noisy_ranges  # the world's kernels: an agent never reads a laser

        scan = np.ascontiguousarray(r.ranges)
        out = np.empty_like(scan)
        noisy_ranges(scan, r.normal(NOISE, self.beams), self.noise, r.noise.factor(self.name), self.range, out)
        return {"laser": out}

    def readings(self) -> dict[str, tuple[tuple[int, ...], str]]:
        return {"laser": ((self.beams,), "<f8")}

    @classmethod
    def tells(cls, spec: Sensor | None, model) -> dict[str, Any]:
        assert spec is None or isinstance(spec, Laser)
        return {"laser_range": None if spec is None else spec.range}


SENSOR = Laser
