"""The grid scenario file's tables as JSON Schema: its top-level keys, [map] or [generator], and the
parameter tables of its controllers and bodies, from the parser's own key sets and parameter classes
(world_server/grid/scenario.py, world_server/grid/params.py); a user's grid controller's table from
its GridController's fields (world_server/grid/face/own.py)."""

from __future__ import annotations

from typing import Any


def schema(controllers: dict[str, Any], installed: bool = True) -> dict[str, Any]:
    """`controllers`: the grid controllers' entries by name; each that is not bundled has a table of
    its own fields (numbers), as the parser takes it."""
    from world_server.arena.schema import INTEGER, NUMBER, STRING, of_dataclass, table
    from world_server.grid.face.layout import CONTROLLERS
    from world_server.grid.face.own import GridController
    from world_server.grid.params import AntParams, CMarkingParams, PhysicsParams
    from world_server.grid.scenario import _TOP_KEYS, GENERATOR_KEYS, Generator

    generator = of_dataclass(Generator)
    generator["required"] = sorted(GENERATOR_KEYS)
    props: dict[str, Any] = {
        "kind": {"const": "grid"},
        "name": STRING,
        "seed": INTEGER,
        "agents": {**INTEGER, "minimum": 1},
        "controller": {
            "anyOf": [{"enum": list(controllers)}, {**STRING, "pattern": ":", "description": "module:NAME"}]
        },
        "q_max": INTEGER,
        "quantity": INTEGER,
        "map": table(
            {"ascii": {**STRING, "description": "rows of # (wall) . (free) B (base) R (resource)"}}, ("ascii",)
        ),
        "generator": generator,
        "ant": of_dataclass(AntParams),
        "cmarking": of_dataclass(CMarkingParams),
        "physics": of_dataclass(PhysicsParams),
    }
    assert set(props) - {"kind"} == _TOP_KEYS, "the grid schema lists every key the parser takes"
    for name, spec in controllers.items():
        try:
            own = None if name in CONTROLLERS else spec.make()
        except Exception:  # a package that does not load: its table is offered open (swarm check says why)
            own = None
            props[name] = {"type": "object", "description": spec.description}
        if not isinstance(own, GridController):
            continue
        fields = {field: {**NUMBER, "description": f"default {default!r}"} for field, default in own.parameters}
        props[name] = {**table(fields), "description": spec.description}
    out = table(props)
    out["oneOf"] = [{"required": ["map"]}, {"required": ["generator"]}]
    out["patternProperties"] = {":": {"type": "object", "description": "the table of a module:NAME grid controller"}}
    return out
