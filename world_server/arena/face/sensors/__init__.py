"""The arena's sensors: one module each in this folder, each declaring `SENSOR`, its class
(base.py: its spec, its rays in the compiled pass, its readings, its noise streams).

`SENSORS` finds them (swarm.core.registry.Registry) in their declared order (`rank`): the ray
blocks of a robot, its readings and its perception follow it.  `Sensors` is what a robot model
carries: one spec per sensor it has."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from swarm.core.registry import Registry
from world_server.arena.face.sensors.base import Rays, Reading, Sensor

__all__ = ["SENSORS", "Rays", "Reading", "Sensor", "Sensors"]

SENSORS: Registry[Any] = Registry("sensor", __name__, "SENSOR", modules=True, key=lambda cls: cls.rank)


@dataclass(frozen=True, init=False)
class Sensors:
    """The sensors of a robot model, in the registry's order: Sensors(camera=Camera(), ir=True)
    (True: the sensor's defaults; None or False: without it).  The sensors every model carries
    (contact, zones) are there unless left out.  `sensors.laser` is the laser's spec, or None."""

    specs: tuple[Sensor, ...]

    def __init__(self, **given: Sensor | bool | None):
        unknown = set(given) - set(SENSORS.names())
        if unknown:
            raise TypeError(f"unknown sensor {sorted(unknown)[0]!r}; expected one of {', '.join(SENSORS.names())}")
        specs = []
        for cls in SENSORS:
            spec = given.get(cls.name, cls.carried)
            if spec is True:
                spec = cls()
            if spec is not None and spec is not False:
                if not isinstance(spec, cls):
                    raise TypeError(f"{cls.name}: expected a {cls.__name__}, got {spec!r}")
                specs.append(spec)
        object.__setattr__(self, "specs", tuple(specs))

    def __getattr__(self, name: str) -> Sensor | None:
        if name.startswith("_") or name == "specs" or name not in SENSORS:
            raise AttributeError(name)
        return next((s for s in self.specs if s.name == name), None)

    def __contains__(self, name: object) -> bool:
        return any(s.name == name for s in self.specs)

    def __iter__(self) -> Iterator[Sensor]:
        return iter(self.specs)

    def names(self) -> list[str]:
        return [s.name for s in self.specs]

    def changed(self, **changes: Sensor | bool | None) -> Sensors:
        """These sensors with some added (a spec, or True for its defaults), replaced or left out (None)."""
        return Sensors(**{**{name: getattr(self, name) for name in SENSORS.names()}, **changes})
