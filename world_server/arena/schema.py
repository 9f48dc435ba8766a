"""The arena scenario file's tables, field by field, as JSON Schema fragments.

The parser (world_server/arena/scenario.py) takes its allowed keys from these tables, so the schema
an editor validates against (`swarm schema`) and the keys the parser accepts are one list.  The
parser stays the judge of everything a schema cannot say (a rect's corners in order, a start
inside the arena, a sensor a controller needs); the schema catches spelling and types as you type.
"""

from __future__ import annotations

import dataclasses
from typing import Any

NUMBER: dict[str, Any] = {"type": "number"}
INTEGER: dict[str, Any] = {"type": "integer"}
STRING: dict[str, Any] = {"type": "string"}
NAME = {**STRING, "description": "a label shown in recordings and plots"}


def numbers(n: int, what: str) -> dict[str, Any]:
    return {"type": "array", "items": NUMBER, "minItems": n, "maxItems": n, "description": what}


POINT = numbers(2, "[x, y] in metres")
RECT = numbers(4, "[x0, y0, x1, y1] in metres, x0 < x1 and y0 < y1")
POSE = {"type": "array", "items": NUMBER, "minItems": 2, "maxItems": 3, "description": "[x, y] or [x, y, theta]"}
COLOUR = {"oneOf": [{"type": "integer", "minimum": 0, "maximum": 255},
                    {"type": "array", "items": {"type": "integer", "minimum": 0, "maximum": 255},
                     "minItems": 3, "maxItems": 3}],
          "description": "a grey level 0-255 or [r, g, b]"}  # fmt: skip
# The BG paper's resources: 50 x 50 cm squares, usable within 70 cm of their centre; a [[resource]]'s
# defaults (its grey by kind: what the camera tells them apart by).
RESOURCE_GREY = {"ingesting": 127, "digesting": 255, "dangerous": 31}
RESOURCE_SIZE, RESOURCE_REACH = 0.5, 0.7
TICKS = {"type": "integer", "minimum": 0, "description": "a tick (control periods from the start)"}

TOP = {
    "kind": {"const": "arena"},
    "name": STRING,
    "description": STRING,
    "seed": INTEGER,
    "size": numbers(2, "[width, height] of the floor in metres"),
    "robot": {},  # filled from the robot models and sensors: robot()
    "noise": {},  # noise()
    "control_period": {**NUMBER, "description": "seconds per tick"},
    "substeps": INTEGER,
    "checkpoint": INTEGER,
    "physics_strips": {**INTEGER, "description": "the floor cut along x into this many physics spaces"},
    "max_ticks": INTEGER,
    "goal_radius": {**NUMBER, "description": "metres"},
    "goal_dwell": {**INTEGER, "description": "ticks inside the goal radius that finish a robot"},
    "wall": {},
    "zone": {},
    "obstacle": {},
    "resource": {},
    "group": {},
    "routes": {
        "type": "object",
        "additionalProperties": {"type": "array", "items": POINT},
        "description": "name = [[x, y], ...]",
    },
    "metabolism": {},
}
ROBOT = {"model": STRING, "name": STRING, "radius": NUMBER, "axle": NUMBER, "max_wheel_speed": NUMBER,
         "max_speed": NUMBER, "max_turn_rate": NUMBER, "colour": COLOUR, "sensors": {}}  # fmt: skip
WALL = {"rect": RECT, "segment": numbers(4, "[x0, y0, x1, y1]: a line"), "colour": COLOUR, "name": NAME}
ZONE = {"kind": STRING, "rect": RECT, "disc": numbers(3, "[cx, cy, r] in metres"), "name": NAME}
OBSTACLE = {"rect": RECT, "appear": TICKS, "vanish": TICKS, "colour": COLOUR, "name": NAME}
RESOURCE = {"kind": STRING, "centre": POINT, "size": NUMBER, "reach": NUMBER, "appear": TICKS, "vanish": TICKS,
            "colour": COLOUR, "name": NAME}  # fmt: skip
GROUP = {"count": {**INTEGER, "minimum": 1}, "controller": STRING, "robot": {}, "start": POSE,
         "starts": {"type": "array", "items": POSE}, "clearance": NUMBER, "goal": POINT,
         "goals": {"type": "array", "items": POINT}, "route": STRING}  # fmt: skip


def table(fields: dict[str, Any], required: tuple[str, ...] = ()) -> dict[str, Any]:
    out: dict[str, Any] = {"type": "object", "properties": fields, "additionalProperties": False}
    if required:
        out["required"] = list(required)
    return out


JSON_TYPES = {bool: "boolean", int: "integer", float: "number", str: "string", tuple: "array", list: "array"}


def of_dataclass(cls) -> dict[str, Any]:
    """A parameter class's table: each field typed by its default, or by its annotation without one."""
    props = {}
    for f in dataclasses.fields(cls):
        default = None if f.default is dataclasses.MISSING else f.default
        kind = type(default) if default is not None else {t.__name__: t for t in JSON_TYPES}.get(str(f.type))
        props[f.name] = {"type": JSON_TYPES[kind]} if kind in JSON_TYPES else {}
        why = next(iter(f.metadata.values()), None)  # swarm.core.params.declared: its provenance
        if why is not None and (text := getattr(why, "reason", "") or getattr(why, "where", "")):
            props[f.name]["description"] = f"{text} (default {default!r})"
    return table(props)


def schema(controllers: dict[str, Any], installed: bool = True) -> dict[str, Any]:
    """The arena scenario file's schema; `controllers`: the arena controllers' entries by name (each
    may have its own [name] table, typed by its parameter classes); with `installed` False, only the
    package's own sensors, not those of installed packages' entry points."""
    from swarm.core.registry import resolve
    from world_server.arena.face.robots import MODELS
    from world_server.arena.face.sensors import SENSORS
    from world_server.arena.face.sensors.zones import ZONE_KINDS
    from world_server.arena.metabolism import MetabolismParams
    from world_server.arena.sensors import NOISE_LEVELS

    classes = SENSORS.including(SENSORS.installed if installed else ())
    tabled = [cls for cls in classes if cls.field_names()]
    sensors = {cls.name: of_dataclass(cls) for cls in tabled}
    names = [cls.name for cls in classes]
    robot_table = table({**ROBOT, "model": {"enum": list(MODELS)},
                         "sensors": {"type": "array", "items": {"enum": names}}, **sensors})  # fmt: skip
    robot = {"oneOf": [{"enum": list(MODELS)}, robot_table], "description": "a model name or a [robot] table"}
    noise = {"oneOf": [{"enum": list(NOISE_LEVELS)},
                       table({"level": {"enum": list(NOISE_LEVELS)}, "map": NUMBER,
                              **{cls.name: NUMBER for cls in tabled}})]}  # fmt: skip
    listed = {
        "wall": table(WALL),
        "zone": table({**ZONE, "kind": {"enum": list(ZONE_KINDS)}}, ("kind",)),
        "obstacle": table(OBSTACLE, ("rect",)),
        "resource": table({**RESOURCE, "kind": {"enum": list(RESOURCE_GREY)}}, ("kind", "centre")),
        "group": table({**GROUP, "robot": robot}),
    }
    props = {**TOP, "robot": robot, "noise": noise, "metabolism": of_dataclass(MetabolismParams)}
    props.update({k: {"type": "array", "items": v} for k, v in listed.items()})
    for name, spec in controllers.items():  # their tables may nest (bg's [bg.gpr]): offered, not closed
        classes = [resolve(ref) for ref in spec.parameters]
        merged = {k: v for cls in classes for k, v in of_dataclass(cls)["properties"].items()}
        props[name] = {"type": "object", "properties": merged, "description": spec.description}
    out = table(props, ("size", "group"))
    out["patternProperties"] = {":": {"type": "object", "description": "the table of a module:Class controller"}}
    return out
