"""Sensor suites: the rays a robot model casts and what its sensors make of them.

This is the simulator face of the sensors (ARGoS's split): which rays leave a
robot, and how ranges and hit colours become readings with noise.  The
controller face is only the perception dict it receives.  All rays of all
robots are cast together by world_server.arena.raycast; a suite reads its block of
the result.  Every noise draw comes from swarm.core.rng keyed by (seed, agent,
tick, stream), so a reading never depends on who else is in the run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swarm.core.rng import fill_normal, fill_uniform
from world_server.arena.face.robots import IR_DISTANCE, IR_VALUE, RobotModel
from world_server.arena.raycast import MARK, SOLID

# Noise streams, one per kind of draw.
S_SONAR_BEARING, S_SONAR_RANGE, S_IR, S_LASER, S_ODOMETRY, S_COMPASS, S_POSITION = range(1, 8)


NOISE_LEVELS = ("none", "low", "high")
POSITION_STD = {"none": 0.0, "low": 0.005, "high": 0.020}  # DFT paper, section 4
MAP_NOISE = {"none": 0.005, "low": 0.05, "high": 1.0}  # DFT code: std per map cell (wall = 1)
LEVEL_SCALE = {"none": 0.0, "low": 1.0, "high": 2.0}  # every other sensor's specified error


@dataclass(frozen=True)
class Noise:
    """How noisy a run is: a level (the DFT paper's none / low / high) and, per
    sensor, a factor on that sensor's specified error."""

    level: str = "low"
    scale: tuple[tuple[str, float], ...] = ()

    def factor(self, sensor: str) -> float:
        return dict(self.scale).get(sensor, 1.0) * LEVEL_SCALE[self.level]

    def position_std(self, specified: float | None) -> float:
        std = POSITION_STD[self.level] if specified is None else specified * LEVEL_SCALE[self.level]
        return std * dict(self.scale).get("position", 1.0)


def ir_response(distance: np.ndarray) -> np.ndarray:
    """Reading of an IR sensor whose ray met something `distance` from the sensor."""
    return np.interp(distance, IR_DISTANCE, IR_VALUE)


def grey(rgb: np.ndarray) -> np.ndarray:
    """Luminance (ITU-R 601) of uint8 colours, as uint8."""
    g = rgb[..., 0] * 0.299 + rgb[..., 1] * 0.587 + rgb[..., 2] * 0.114
    return np.rint(g).astype(np.uint8)


def wrap(angle):
    """Into [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


class Suite:
    """The sensors of one robot model for a group of robots (global ids `robots`)."""

    def __init__(self, model: RobotModel, robots: np.ndarray, noise: Noise, seed: int):
        self.model, self.robots, self.noise, self.seed = model, np.asarray(robots, np.int64), noise, seed
        s = model.sensors
        bearings, ranges, offsets, masks = [], [], [], []
        self.blocks: dict[str, slice] = {}

        def add(name: str, b: np.ndarray, rng: float, offset: float = 0.0) -> None:
            start = sum(len(x) for x in bearings)
            bearings.append(np.asarray(b, np.float64))
            ranges.append(np.full(len(b), rng + offset))
            offsets.append(np.full(len(b), offset))
            masks.append(np.full(len(b), SOLID | MARK if name == "camera" else SOLID, np.uint8))
            self.blocks[name] = slice(start, start + len(b))

        if s.camera:
            c = s.camera
            width = 2 * math.pi / c.sectors
            sub = (np.arange(c.rays_per_sector) + 0.5) / c.rays_per_sector - 0.5
            add("camera", (np.arange(c.sectors)[:, None] + sub[None, :]).ravel() * width, c.range)
        if s.sonar:
            o = s.sonar
            cone = np.linspace(-o.beam_width / 2, o.beam_width / 2, o.cone_rays) if o.cone_rays > 1 else np.zeros(1)
            centres = np.arange(o.count) * 2 * math.pi / o.count
            add("sonar", (centres[:, None] + cone[None, :]).ravel(), o.range)
        if s.ir:
            add("ir", np.array(s.ir.bearings), s.ir.range, model.ir_mounts())
        if s.laser:
            la = s.laser
            full = la.fov >= 2 * math.pi - 1e-9
            b = (np.arange(la.beams) / la.beams * la.fov if full
                 else np.linspace(-la.fov / 2, la.fov / 2, la.beams))  # fmt: skip
            add("laser", b, la.range)
        self.bearings = np.concatenate(bearings) if bearings else np.zeros(0)
        self.ranges = np.concatenate(ranges) if ranges else np.zeros(0)
        self.offsets = np.concatenate(offsets) if offsets else np.zeros(0)
        self.masks = np.concatenate(masks) if masks else np.zeros(0, np.uint8)
        self.per_robot = len(self.bearings)
        n = len(self.robots)
        bearing = np.tile(self.bearings, n)  # the group's rays, robot-major, without noise
        self._fixed = (np.repeat(self.robots, self.per_robot), bearing, np.tile(self.ranges, n), np.cos(bearing),
                       np.sin(bearing), np.tile(self.masks, n))  # fmt: skip

    # ------------------------------------------------------------------ rays

    def rays(self, tick: int) -> tuple[np.ndarray, ...]:
        """(robot, bearing, range, cos, sin of bearing, layer mask) of every ray
        of the group, robot-major (cameras see marks, range sensors only
        solids).  The sonar's bearing error turns each cone as a whole; the
        other bearings are fixed, so their cosines are computed once."""
        n = len(self.robots)
        sonar = self.model.sensors.sonar
        if not (sonar and self.noise.factor("sonar") and sonar.bearing_error):
            return self._fixed
        robot, bearing, ranges, c, s, masks = self._fixed
        u = self._uniform(S_SONAR_BEARING, sonar.count, tick) * sonar.bearing_error * self.noise.factor("sonar")
        turned = bearing.reshape(n, self.per_robot).copy()
        turned[:, self.blocks["sonar"]] += np.repeat(u, sonar.cone_rays, axis=1)
        turned = turned.ravel()
        c, s = c.copy(), s.copy()
        b = np.zeros((n, self.per_robot), np.bool_)
        b[:, self.blocks["sonar"]] = True
        b = b.ravel()
        c[b], s[b] = np.cos(turned[b]), np.sin(turned[b])
        return robot, turned, ranges, c, s, masks

    def _uniform(self, stream: int, k: int, tick: int) -> np.ndarray:
        out = np.empty((len(self.robots), k))
        fill_uniform(np.int64(self.seed), self.robots, np.int64(tick), np.int64(stream), out)
        return out

    def _normal(self, stream: int, k: int, tick: int) -> np.ndarray:
        out = np.empty((len(self.robots), k))
        fill_normal(np.int64(self.seed), self.robots, np.int64(tick), np.int64(stream), out)
        return out

    # --------------------------------------------------------------- reading

    def read(self, ranges: np.ndarray, rgb: np.ndarray, what: np.ndarray, state, tick: int) -> dict[str, np.ndarray]:
        """Readings of every robot of the group.  `ranges`, `rgb`, `what` are this
        group's rays (n, per_robot[, 3]); `state` is the world (poses, motion,
        contacts, zones) indexed by global robot id."""
        s, n, out = self.model.sensors, len(self.robots), {}
        ranges = ranges - self.offsets[None, :]
        if s.camera:
            c, b = s.camera, self.blocks["camera"]
            r = ranges[:, b].reshape(n, c.sectors, c.rays_per_sector)
            near = np.argmin(r, axis=2)
            pick = (np.arange(n)[:, None], np.arange(c.sectors)[None, :])
            out["camera_range"] = r[(*pick, near)]
            colours = rgb[:, b].reshape(n, c.sectors, c.rays_per_sector, 3)
            out["camera_rgb"] = colours[(*pick, near)]
            out["camera_grey"] = grey(out["camera_rgb"])
            out["camera_what"] = what[:, b].reshape(n, c.sectors, c.rays_per_sector)[(*pick, near)]
        if s.sonar:
            o, b = s.sonar, self.blocks["sonar"]
            echo = ranges[:, b].reshape(n, o.count, o.cone_rays).min(axis=2)
            echo = echo + self._uniform(S_SONAR_RANGE, o.count, tick) * o.range_error * self.noise.factor("sonar")
            out["sonar"] = np.clip(echo, 0.0, o.range)
        if s.ir:
            b = self.blocks["ir"]
            distance = np.maximum(ranges[:, b], 0.0)
            if s.ir.red_sensitivity:
                red = state.hit_colours(what[:, b].ravel())[:, 0].reshape(n, -1) / 255.0
                distance = distance + (distance / (0.2 + 0.8 * red) - distance) * s.ir.red_sensitivity
            # nothing within the curve's range reads 0 (ambient light subtracted), also when only the colour puts it out
            reading = np.where((what[:, b] == -1) | (distance > IR_DISTANCE[-1]), 0.0, ir_response(distance))
            if s.ir.noise:
                k = len(s.ir.bearings)
                reading = reading * (1.0 + self._normal(S_IR, k, tick) * s.ir.noise * self.noise.factor("ir"))
            out["ir"] = np.maximum(reading, 0.0)
        if s.laser:
            la = s.laser
            scan = ranges[:, self.blocks["laser"]]
            noisy = scan + self._normal(S_LASER, la.beams, tick) * la.noise * self.noise.factor("laser")
            out["laser"] = np.where(scan >= la.range, la.range, np.clip(noisy, 0.0, la.range))
        rows = self.robots
        if s.odometry:
            err = self._uniform(S_ODOMETRY, 2, tick) * s.odometry.error * self.noise.factor("odometry")
            out["odometry"] = state.motion[rows] * (1.0 + err)
        if s.compass:
            e = self._uniform(S_COMPASS, 1, tick)[:, 0] * s.compass.error * self.noise.factor("compass")
            out["compass"] = (state.pose[rows, 2] + e) % (2 * math.pi)
        if s.position:
            std = self.noise.position_std(s.position.std)
            out["position"] = state.pose[rows, :2] + self._normal(S_POSITION, 2, tick) * std
        if s.contact:
            out["contact"] = state.contact[rows].copy()
        if s.zones:
            out["zones"] = state.zones[rows].copy()
        if getattr(state, "metabolism", None) is not None:  # internal sensors: E and Ep
            out["metabolism"] = state.metabolism.levels(rows)
        return out
