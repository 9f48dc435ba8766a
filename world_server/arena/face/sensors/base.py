"""What every sensor of the arena's robots declares (one module each in this folder).

A sensor is a frozen dataclass: its fields are its spec (what a scenario's `[robot.<name>]` table
may set), and its methods are its part of a tick: the rays it adds to the compiled ray pass, the
bearing noise that turns them, and how it makes its readings of their results and of the world's
state.  Its noise draws come through the `Reading` it is handed (swarm.core.rng keyed by (seed,
robot, tick, stream) in the world's suite: world_server/arena/sensors.py), so a sensor module
imports numpy only, and an agent process may read the specs without loading the world.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, fields, replace
from typing import Any, ClassVar

import numpy as np

DEG = math.pi / 180.0


@dataclass(frozen=True)
class Rays:
    """The rays one sensor casts from each robot's centre: bearings from the heading (radians,
    counter-clockwise), the most each reports (from the sensor), how far each sensor sits from
    the centre (its range is counted from there), whether they see the marks only cameras see,
    and whether its reading needs the colours of what they hit."""

    bearings: np.ndarray
    range: float
    offsets: float | np.ndarray = 0.0
    marks: bool = False
    colours: bool = False


@dataclass(frozen=True)
class Reading:
    """What a sensor makes its readings of, for the n robots of one group at one tick.

    `uniform(stream, k)` and `normal(stream, k)` are the robots' (n, k) draws of a noise stream at
    this tick (uniform in [-1, 1), standard normal); `per_run(stream, k)` the robots' uniform draws
    that stay the same every tick of the run (a sensor's bias).  `noise` is the run's noise
    (world_server.arena.sensors.Noise: `factor(name)` scales a sensor's specified error).
    `state` is the world, indexed by global robot id: pose, motion, contact, zones, in_world,
    present, hit_colours(what), in_sight(...) and the broadcasts (range_bearing.py).  `ranges`,
    `what` and `rgb` are this sensor's rays, (n, rays[, 3]): the range from the sensor, what each
    hit (raycast.py: a segment >= 0, nothing -1, robot -2 - id) and its colour (only for rays that
    asked for colours)."""

    robots: np.ndarray
    tick: int
    noise: Any
    uniform: Callable[[int, int], np.ndarray]
    normal: Callable[[int, int], np.ndarray]
    state: Any = None
    ranges: np.ndarray | None = None
    what: np.ndarray | None = None
    rgb: np.ndarray | None = None
    per_run: Callable[[int, int], np.ndarray] | None = None


class Sensor:
    """The base of every sensor.  A subclass declares `name`, `rank` (its place in a suite: the
    order of the ray blocks and of the readings), `streams` (the noise streams it draws from, one
    per kind of draw, unique across sensors) and, if every model carries it, `carried`."""

    name: ClassVar[str]
    rank: ClassVar[int]
    streams: ClassVar[tuple[int, ...]] = ()
    carried: ClassVar[bool] = False  # carried by a model that does not name its sensors (contact, zones)

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        """The fields a scenario's table may set (none: the sensor has no table)."""
        return tuple(f.name for f in fields(cls))  # type: ignore[arg-type]

    @classmethod
    def from_table(cls, table: dict[str, Any], base: Sensor | None = None) -> Sensor:
        """This sensor's spec from a scenario's table, over `base` (default: its defaults).  A list
        is a tuple of numbers, a switch (a bool field) true or false, an integer field an integer, the rest numbers;
        ValueError("field: what is expected") on a bad one."""
        base = base if base is not None else cls()
        known = cls.field_names()
        typed = {}
        for k, v in table.items():
            if k not in known:
                raise ValueError(f"{k}: unknown field; expected one of {', '.join(sorted(known))}")
            was = getattr(base, k)
            if isinstance(was, bool):  # a switch: true or false, not a number
                if not isinstance(v, bool):
                    raise ValueError(f"{k}: expected true or false, got {v!r}")
                typed[k] = v
                continue
            try:
                typed[k] = (tuple(float(x) for x in v) if isinstance(v, list) else
                            int(v) if isinstance(was, int) and not isinstance(was, bool) else float(v))  # fmt: skip
            except (TypeError, ValueError):
                raise ValueError(f"{k}: expected {'a list of numbers' if isinstance(was, tuple) else 'a number'}, "
                                 f"got {v!r}") from None  # fmt: skip
        spec = replace(base, **typed)  # type: ignore[type-var]
        spec.check_counts()
        return spec

    def check_counts(self) -> None:
        """ValueError("field: ...") for a count (an integer field) under 1."""
        for f in fields(self):  # type: ignore[arg-type]
            v = getattr(self, f.name)
            if isinstance(v, int) and not isinstance(v, bool) and v < 1:
                raise ValueError(f"{f.name}: expected a count of at least 1, got {v}")

    def check(self, model) -> None:
        """ValueError("field: ...") if this spec does not fit the robot `model` (its radius)."""

    def rays(self, model) -> Rays | None:
        """The rays it adds to the ray pass for a robot of `model`, or None."""
        return None

    def turn(self, r: Reading) -> np.ndarray | None:
        """Its bearing noise this tick: (n, rays) added to its rays' bearings, or None."""
        return None

    def read(self, r: Reading) -> dict[str, np.ndarray]:
        """Its readings of the group's robots, each an array with a robot axis first."""
        raise NotImplementedError

    def readings(self) -> dict[str, tuple[tuple[int, ...], str]]:
        """The shape (per robot) and dtype of each reading `read` returns."""
        raise NotImplementedError

    @classmethod
    def tells(cls, spec: Sensor | None, model) -> dict[str, Any]:
        """What a controller of a robot of `model` is told of this sensor before it starts (plain
        data in params["robot"]; the keys are there, None, when the robot lacks the sensor)."""
        return {}
