"""Infrared proximity sensors (the e-puck's ps0..ps7, read as Webots reads them: docs/arena.md)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from world_server.arena.face.sensors.base import Rays, Reading, Sensor

NOISE = 3  # noise stream: the relative error of a reading

# IR response: reading against distance from the sensor (m), piecewise linear, 0 when the
# ray meets nothing within range.  The shape of the e-puck calibration curves Webots
# uses (4095 at contact, about 67 at 7 cm); the DFT controller only uses log(1 + p/50).
IR_DISTANCE = np.array([0.0, 0.005, 0.01, 0.015, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07])
IR_VALUE = np.array([4095.0, 2133.0, 1465.0, 601.0, 383.0, 234.0, 158.0, 120.0, 104.0, 67.0])


def ir_response(distance: np.ndarray) -> np.ndarray:
    """Reading of an IR sensor whose ray met something `distance` from the sensor."""
    return np.interp(distance, IR_DISTANCE, IR_VALUE)


@dataclass(frozen=True)
class IR(Sensor):
    """Infrared proximity sensors looking out from the robot: a reading from the
    documented response curve of the distance from the sensor (docs/arena.md)."""

    name = "ir"
    rank = 2
    streams = (NOISE,)

    bearings: tuple[float, ...] = (-0.30, -0.80, -1.57, -2.64, 2.64, 1.57, 0.80, 0.30)  # e-puck ps0..ps7
    range: float = 0.07
    # How far each sensor sits from the robot's centre (m); None: on the rim.  Distances are measured
    # from the sensor, as Webots measures them, so a sensor inside the body reads a touching wall as
    # (rim - mount) away, not as 0.
    mounts: tuple[float, ...] | None = None
    noise: float = 0.0  # relative std of a reading
    # Webots' infra-red model (the DFT paper's simulator): a surface reflects by f = 0.2 + 0.8 * red level,
    # and the sensor reads the curve at d + (d / f - d) * red_sensitivity (Webots' redColorSensitivity,
    # default 1): a dark or non-red surface seems farther.  0 reads the curve at the true distance.
    red_sensitivity: float = 1.0

    def mounts_on(self, radius: float) -> np.ndarray:
        """Each sensor's distance from the centre of a robot of this radius, where its range is
        measured from (ValueError if unusable)."""
        if self.mounts is None:
            return np.full(len(self.bearings), radius)
        mounts = np.asarray(self.mounts, np.float64)
        if mounts.shape != (len(self.bearings),) or not np.all((mounts > 0) & (mounts <= radius)):
            raise ValueError(f"mounts: give one distance in (0, radius = {radius}] per bearing "
                             f"({len(self.bearings)}), or leave it out for sensors on the rim")  # fmt: skip
        return mounts

    def check(self, model) -> None:
        self.mounts_on(model.radius)

    def rays(self, model) -> Rays:
        return Rays(np.array(self.bearings), self.range, self.mounts_on(model.radius))

    def read(self, r: Reading) -> dict[str, np.ndarray]:
        assert r.ranges is not None and r.what is not None
        distance = np.maximum(r.ranges, 0.0)
        if self.red_sensitivity:
            red = r.state.hit_colours(r.what.ravel())[:, 0].reshape(len(r.robots), -1) / 255.0
            distance = distance + (distance / (0.2 + 0.8 * red) - distance) * self.red_sensitivity
        # nothing within the curve's range reads 0 (ambient light subtracted), also when only the colour puts it out
        reading = np.where((r.what == -1) | (distance > IR_DISTANCE[-1]), 0.0, ir_response(distance))
        if self.noise:
            reading = reading * (1.0 + r.normal(NOISE, len(self.bearings)) * self.noise * r.noise.factor(self.name))
        return {"ir": np.maximum(reading, 0.0)}

    def readings(self) -> dict[str, tuple[tuple[int, ...], str]]:
        return {"ir": ((len(self.bearings),), "<f8")}

    @classmethod
    def tells(cls, spec: Sensor | None, model) -> dict[str, Any]:
        assert spec is None or isinstance(spec, IR)
        return {"ir_bearings": None if spec is None else list(spec.bearings),
                "ir_mounts": None if spec is None else spec.mounts_on(model.radius).tolist()}  # fmt: skip


SENSOR = IR
