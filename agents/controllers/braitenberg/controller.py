"""The Braitenberg vehicle: wheel speeds as a fixed linear map of the infrared readings.

Each wheel's speed is sum_j w[j, wheel] * (1 - ir_j / range), in the wheel's rad/s, scaled to the
robot's wheel limit: with nothing in view both wheels turn at the same speed, and a reading on one
side slows the wheel on that side and speeds the other, so the robot turns away (Braitenberg's
vehicle 3b, "explorer").  The weights are the Webots e-puck demonstration controller's, so on the
e-puck it behaves as that controller does; it has no state, no randomness and no memory, which makes
it the smallest complete example of the controller face (agents/controllers/arena.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from swarm.core.params import CODE, declared
from swarm.core.tables import params_from_table

_WEBOTS = "Webots, projects/robots/gctronic/e-puck/controllers/e-puck: braitenberg_coefficients"


@dataclass(frozen=True)
class BraitenbergParams:
    """The Webots e-puck controller's numbers; `weights` lists (left, right) for ps0..ps7."""

    weights: tuple[tuple[float, float], ...] = declared(
        ((0.942, -0.22), (0.63, -0.1), (0.5, -0.06), (-0.06, -0.06),
         (-0.06, -0.06), (-0.06, 0.5), (-0.19, 0.63), (-0.13, 0.942)),
        source=CODE, where=_WEBOTS,
    )  # fmt: skip
    range: float = declared(512.0, source=CODE, where="the same controller: RANGE = 1024 / 2")
    top_speed: float = declared(6.28, source=CODE, where="the same controller: the e-puck's wheel limit, rad/s")

    def __post_init__(self) -> None:
        try:
            w = np.asarray(self.weights, np.float64)
        except (TypeError, ValueError):
            w = np.zeros(0)
        if w.ndim != 2 or w.shape[1] != 2 or not np.isfinite(w).all():
            raise ValueError("[braitenberg] weights: give one [left, right] pair of numbers per IR sensor")
        if not (self.range > 0 and self.top_speed > 0):
            raise ValueError("[braitenberg] range and top_speed: expected positive numbers")
        object.__setattr__(self, "weights", tuple(map(tuple, w.tolist())))  # a table's lists, frozen

    @classmethod
    def from_table(cls, table: dict[str, Any] | None) -> BraitenbergParams:
        return params_from_table(cls, table, "braitenberg", texts=("weights",))


class BraitenbergController:
    def reset(self, seed: int, agent: int, params: dict[str, Any]) -> None:
        self.p = BraitenbergParams.from_table(params.get("braitenberg"))
        self.weights = np.asarray(self.p.weights, np.float64)
        self.max_wheel = float(params["robot"]["max_wheel_speed"])
        sensors = len(params["robot"].get("ir_bearings") or ())
        if sensors != len(self.weights):
            raise ValueError(f"braitenberg: {len(self.weights)} weight pairs for a robot with {sensors} IR "
                             "sensors; give [braitenberg] weights one pair per sensor")  # fmt: skip
        self.wheels = np.zeros(2)

    def step(self, perception: dict[str, np.ndarray]) -> np.ndarray:
        ir = np.asarray(perception["ir"], np.float64)
        speed = (1.0 - ir / self.p.range) @ self.weights  # rad/s of the left and right wheels
        self.wheels = np.clip(speed / self.p.top_speed, -1.0, 1.0) * self.max_wheel
        return self.wheels.copy()

    def snapshot(self) -> dict[str, Any]:
        return {"wheels": self.wheels.tolist()}

    def restore(self, state: dict[str, Any]) -> None:
        self.wheels = np.asarray(state["wheels"], np.float64)

    def record(self) -> dict[str, np.ndarray]:
        return {"wheels": self.wheels.copy()}
