"""The zone sensor: which kinds of zone the robot's centre is in."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from world_server.arena.face.sensors.base import Reading, Sensor

# The `zones` reading is a bit field: bit k set when the robot is in a zone of kind ZONE_KINDS[k].
ZONE_KINDS = ("goal", "ingesting", "digesting", "dangerous", "start", "place")


@dataclass(frozen=True)
class Zones(Sensor):
    """Bit k set when the robot's centre is in a zone of kind ZONE_KINDS[k] (no noise)."""

    name = "zones"
    rank = 8
    carried = True

    def read(self, r: Reading) -> dict[str, np.ndarray]:
        return {"zones": r.state.zones[r.robots].copy()}

    def readings(self) -> dict[str, tuple[tuple[int, ...], str]]:
        return {"zones": ((), "<i8")}


SENSOR = Zones
