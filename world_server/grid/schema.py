"""The grid scenario file's tables as JSON Schema: its top-level keys, [map] or [generator], and the
parameter tables of its controllers and bodies, from the parser's own key sets and parameter classes
(world_server/grid/scenario.py, world_server/grid/params.py)."""

from __future__ import annotations

from typing import Any


def schema(controllers: dict[str, Any], installed: bool = True) -> dict[str, Any]:
    from world_server.arena.schema import INTEGER, STRING, of_dataclass, table
    from world_server.grid.params import AntParams, CMarkingParams, PhysicsParams
    from world_server.grid.scenario import _TOP_KEYS, GENERATOR_KEYS, Generator

    generator = of_dataclass(Generator)
    generator["required"] = sorted(GENERATOR_KEYS)
    props: dict[str, Any] = {
        "kind": {"const": "grid"},
        "name": STRING,
        "seed": INTEGER,
        "agents": {**INTEGER, "minimum": 1},
        "controller": {"enum": list(controllers)},
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
    out = table(props)
    out["oneOf"] = [{"required": ["map"]}, {"required": ["generator"]}]
    return out
