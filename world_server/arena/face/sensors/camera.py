"""The panoramic linear camera (the BG paper's animat; the scout's colour camera)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from world_server.arena.face.sensors.base import Rays, Reading, Sensor

COLOUR, RANGE = 10, 11  # noise streams: each sector's colour error, its range error


def grey(rgb: np.ndarray) -> np.ndarray:
    """Luminance (ITU-R 601) of uint8 colours, as uint8."""
    g = rgb[..., 0] * 0.299 + rgb[..., 1] * 0.587 + rgb[..., 2] * 0.114
    return np.rint(g).astype(np.uint8)


@dataclass(frozen=True)
class Camera(Sensor):
    """Panoramic linear camera: per sector the colour, grey level and distance
    of the nearest wall or robot among `rays_per_sector` rays spread over it,
    each colour channel off by a normal error of std `noise` (colour levels,
    0-255, rounded and clipped) and each distance by one of std `range_noise`
    (metres), both drawn afresh every tick and sector.  Both are 0 unless a
    scenario sets them: the camera then reads exactly what its rays hit."""

    name = "camera"
    rank = 0
    streams = (COLOUR, RANGE)

    sectors: int = 36
    rays_per_sector: int = 5
    range: float = 30.0
    noise: float = 0.0  # std of each colour channel, levels
    range_noise: float = 0.0  # std of each sector's distance, metres

    def rays(self, model) -> Rays:
        width = 2 * math.pi / self.sectors
        sub = (np.arange(self.rays_per_sector) + 0.5) / self.rays_per_sector - 0.5
        bearings = (np.arange(self.sectors)[:, None] + sub[None, :]).ravel() * width
        return Rays(bearings, self.range, marks=True, colours=True)  # cameras see the marks, and their colours

    def read(self, r: Reading) -> dict[str, np.ndarray]:
        assert r.ranges is not None and r.rgb is not None and r.what is not None
        n, k = len(r.robots), (self.sectors, self.rays_per_sector)
        ranges = r.ranges.reshape(n, *k)
        near = np.argmin(ranges, axis=2)
        pick = (np.arange(n)[:, None], np.arange(self.sectors)[None, :], near)
        rgb, seen = r.rgb.reshape(n, *k, 3)[pick], ranges[pick]
        factor = r.noise.factor(self.name)
        if self.noise and factor:
            noisy = rgb + r.normal(COLOUR, self.sectors * 3).reshape(n, self.sectors, 3) * self.noise * factor
            rgb = np.clip(np.rint(noisy), 0, 255).astype(np.uint8)
        if self.range_noise and factor:
            seen = np.clip(seen + r.normal(RANGE, self.sectors) * self.range_noise * factor, 0.0, self.range)
        return {"camera_range": seen, "camera_rgb": rgb, "camera_grey": grey(rgb),
                "camera_what": r.what.reshape(n, *k)[pick]}  # fmt: skip

    def readings(self) -> dict[str, tuple[tuple[int, ...], str]]:
        s = self.sectors
        return {"camera_range": ((s,), "<f8"), "camera_rgb": ((s, 3), "|u1"), "camera_grey": ((s,), "|u1"),
                "camera_what": ((s,), "<i8")}  # fmt: skip


SENSOR = Camera
