"""The contact sensor: touched a wall or a robot in the last period."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from world_server.arena.face.sensors.base import Reading, Sensor


@dataclass(frozen=True)
class Contact(Sensor):
    """True when the robot touched a wall or a robot in the last period (no noise)."""

    name = "contact"
    rank = 7
    carried = True

    def read(self, r: Reading) -> dict[str, np.ndarray]:
        return {"contact": r.state.contact[r.robots].copy()}

    def readings(self) -> dict[str, tuple[tuple[int, ...], str]]:
        return {"contact": ((), "|b1")}


SENSOR = Contact
