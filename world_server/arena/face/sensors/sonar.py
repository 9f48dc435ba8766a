"""The animat's ring of sonars (Girard et al. 2005: 5 m, +-5 deg, +-10 cm)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from world_server.arena.face.sensors.base import DEG, Rays, Reading, Sensor

BEARING, RANGE = 1, 2  # noise streams: the cone's turn, the echo's error


@dataclass(frozen=True)
class Sonar(Sensor):
    """Ring of sonars; each is a cone of `cone_rays` rays over `beam_width`
    reporting its nearest echo, with a bearing error (the whole cone turns)
    and a distance error, both uniform within their bounds."""

    name = "sonar"
    rank = 1
    streams = (BEARING, RANGE)

    count: int = 8
    range: float = 5.0
    beam_width: float = 15 * DEG
    cone_rays: int = 3
    bearing_error: float = 5 * DEG
    range_error: float = 0.10

    def rays(self, model) -> Rays:
        half = self.beam_width / 2
        cone = np.linspace(-half, half, self.cone_rays) if self.cone_rays > 1 else np.zeros(1)
        centres = np.arange(self.count) * 2 * math.pi / self.count
        return Rays((centres[:, None] + cone[None, :]).ravel(), self.range)

    def turn(self, r: Reading) -> np.ndarray | None:
        """Each cone turns as a whole by its bearing error."""
        factor = r.noise.factor(self.name)
        if not (factor and self.bearing_error):
            return None
        u = r.uniform(BEARING, self.count) * self.bearing_error * factor
        return np.repeat(u, self.cone_rays, axis=1)

    def read(self, r: Reading) -> dict[str, np.ndarray]:
        assert r.ranges is not None
        echo = r.ranges.reshape(len(r.robots), self.count, self.cone_rays).min(axis=2)
        echo = echo + r.uniform(RANGE, self.count) * self.range_error * r.noise.factor(self.name)
        return {"sonar": np.clip(echo, 0.0, self.range)}

    def readings(self) -> dict[str, tuple[tuple[int, ...], str]]:
        return {"sonar": ((self.count,), "<f8")}


SENSOR = Sonar
