"""The Gymnasium spaces of an arena robot, from its model: one Box per reading its sensors declare
(`Sensor.readings()`: shape and dtype), bounded where the sensor bounds it, and its actions: wheel
speeds, and the act and broadcast of a robot that has them."""

from __future__ import annotations

import math

import numpy as np
from gymnasium import spaces

from world_server.arena.face.robots import RobotModel
from world_server.arena.face.sensors.base import Sensor
from world_server.arena.face.sensors.range_bearing import RangeAndBearing
from world_server.arena.face.sensors.zones import ZONE_KINDS
from world_server.arena.metabolism import ACTS


def reading_bounds(sensor: Sensor, key: str, dtype: np.dtype) -> tuple[float, float]:
    """(low, high) of one reading: the sensor's range where it clips to one, the dtype's
    limits otherwise (an unbounded float is -inf..inf; padding rows of rab_distance are +inf)."""
    known = {
        "ir": (0.0, math.inf),
        "laser": (0.0, getattr(sensor, "range", math.inf)),
        "sonar": (0.0, getattr(sensor, "range", math.inf)),
        "compass": (0.0, 2 * math.pi),
        "camera_range": (0.0, math.inf),
        "rab_distance": (0.0, math.inf),
        "rab_count": (0, getattr(sensor, "max_neighbours", np.iinfo(np.int64).max)),
        "zones": (0, 2 ** len(ZONE_KINDS) - 1),
    }
    if key in known:
        return known[key]
    if dtype.kind == "b":
        return (0, 1)
    if dtype.kind in "ui":
        info = np.iinfo(dtype)
        return (int(info.min), int(info.max))
    return (-math.inf, math.inf)


def observation_space(model: RobotModel, metabolism: bool = False) -> spaces.Dict:
    """One Box per reading of the model's sensors, in the suite's order; `metabolism` adds the
    internal (E, Ep) levels a scenario with a metabolism reads."""
    boxes: dict[str, spaces.Box] = {}
    for sensor in model.sensors.specs:
        for key, (shape, dt) in sensor.readings().items():
            dtype = np.dtype(dt)
            low, high = reading_bounds(sensor, key, dtype)
            boxes[key] = spaces.Box(low, high, shape, dtype)
    if metabolism:
        boxes["metabolism"] = spaces.Box(-math.inf, math.inf, (2,), np.float64)
    return spaces.Dict(boxes)


def action_space(model: RobotModel, metabolism: bool = False) -> spaces.Box | spaces.Dict:
    """Left and right wheel speeds (m/s), each within the model's limit.  A robot that can do more
    than drive gets a Dict of them under `wheels`, with `act` (the consummatory act it asks for,
    world_server.arena.metabolism.ACTS) where the scenario has a metabolism, and `broadcast` (the
    bytes its range-and-bearing sensor sends this tick) where it carries one."""
    w = float(model.max_wheel_speed)
    wheels = spaces.Box(-w, w, (2,), np.float32)
    more: dict[str, spaces.Space] = {}
    if metabolism:
        more["act"] = spaces.Discrete(len(ACTS))
    rab = next((s for s in model.sensors.specs if s.name == RangeAndBearing.name), None)
    if rab is not None:
        more["broadcast"] = spaces.Box(0, 255, (rab.payload,), np.uint8)
    return spaces.Dict({"wheels": wheels, **more}) if more else wheels
