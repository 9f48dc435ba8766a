"""The arena's sensors: one module each in this folder, each declaring `SENSOR`, its class
(base.py: its spec, its rays in the compiled pass, its readings, its noise streams).

`SENSORS` finds them (swarm.core.registry.Registry) in their declared order (`rank`): the ray
blocks of a robot, its readings and its perception follow it.  `Sensors` is what a robot model
carries: one spec per sensor it has.

An installed package may add a sensor: its entry point of the group `swarm.sensors` names its class
(`installed_sensor` says what the arena takes).  Its module is imported only when a scenario's robot
carries it, or when every sensor is asked for (the full schema, the registry's tests)."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, is_dataclass
from typing import Any

from swarm.core.registry import Refused, Registry, resolve
from world_server.arena.face.sensors.base import Rays, Reading, Sensor

__all__ = ["SENSORS", "Rays", "Reading", "Sensor", "Sensors"]


def installed_sensor(name: str, reference: str) -> type[Sensor]:
    """The sensor class an installed package's entry point names (group `swarm.sensors`), imported
    now; Refused, in one line saying what to do, for one the arena cannot take: not a Sensor
    dataclass, known by another name than its entry point's, or drawing its place (`rank`) or a
    noise stream another sensor has (its noise would be that sensor's)."""
    cls = resolve(reference)
    if not (isinstance(cls, type) and issubclass(cls, Sensor) and is_dataclass(cls)):
        raise Refused(f"{reference} is not a Sensor class; name a @dataclass(frozen=True) subclass of "
                      "world_server.arena.face.sensors.Sensor (docs/sensors.md)")  # fmt: skip
    if getattr(cls, "name", None) != name:
        raise Refused(f"{reference} says name = {getattr(cls, 'name', None)!r}; give the entry point and the "
                      "class the same name (one no built-in sensor has)")  # fmt: skip
    if cls.carried:
        raise Refused(f"{reference} says carried = True; a sensor of another package is carried only by the "
                      "robots whose scenario names it: leave carried out")  # fmt: skip
    others = [c for c in SENSORS.known().values() if c is not cls]
    rank = getattr(cls, "rank", None)
    if not isinstance(rank, int) or isinstance(rank, bool):
        raise Refused(f"{reference} declares no integer rank; give it one no other sensor has")
    if taken := next((c for c in others if c.rank == rank), None):
        raise Refused(f"{reference} has rank {rank}, which sensor {taken.name!r} has; give it a rank no other "
                      f"sensor has (taken: {', '.join(str(c.rank) for c in others)})")  # fmt: skip
    streams = tuple(cls.streams)
    if not all(isinstance(k, int) and not isinstance(k, bool) and k > 0 for k in streams):
        raise Refused(f"{reference} declares streams {streams!r}; its noise streams are positive integers")
    if len(set(streams)) < len(streams):
        raise Refused(f"{reference} declares a noise stream twice {streams!r}; give each kind of draw its own")
    for other in others:
        if shared := sorted(set(streams) & set(other.streams)):
            taken_streams = sorted(k for c in others for k in c.streams)
            raise Refused(f"{reference} draws noise stream {shared[0]}, which sensor {other.name!r} draws; give it "
                          f"streams no other sensor has (taken: {', '.join(map(str, taken_streams))})")  # fmt: skip
    return cls


SENSORS: Registry[Any] = Registry("sensor", __name__, "SENSOR", modules=True, key=lambda cls: cls.rank,
                                  plugins="swarm.sensors", external=installed_sensor, references=False)  # fmt: skip


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
        wanted = [name for name, spec in given.items() if spec is not None and spec is not False]
        for cls in SENSORS.including(wanted):  # an installed sensor is imported only when a robot carries it
            spec = given.get(cls.name, cls.carried)
            if spec is True:
                spec = cls()
            if spec is not None and spec is not False:
                if not isinstance(spec, cls):
                    raise TypeError(f"{cls.name}: expected a {cls.__name__}, got {spec!r}")
                specs.append(spec)
        if missing := set(wanted) - {s.name for s in specs}:
            raise TypeError(f"sensor {sorted(missing)[0]!r} cannot be loaded (said above)")
        object.__setattr__(self, "specs", tuple(specs))

    def __getattr__(self, name: str) -> Sensor | None:
        if name.startswith("_") or name == "specs" or name not in SENSORS.names():
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
