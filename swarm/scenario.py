"""Scenarios: a preset, a bundled name or a TOML file, read into its world kind's scenario.

A file's `kind` names its world kind (world_server.WORLD_KINDS; a file without one is of the
default kind, the grid), and the kind parses the rest (world_server/<kind>/scenario.py).  Every
error is a ScenarioError naming the file and the field.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path
from typing import TYPE_CHECKING

from agents.controllers import CONTROLLERS
from swarm.core.errors import ScenarioError
from swarm.core.registry import UnknownPart, resolve
from world_server import world_kind
from world_server.grid.scenario import Scenario, paper_setup

if TYPE_CHECKING:
    from world_server.arena.scenario import ArenaScenario

PRESET_HELP = "setup1, setup2, setup3-<size> (paper sizes 12, 25, 50, 100, 200)"
BUNDLED_DIR = Path(__file__).parent / "scenarios"


def bundled_scenarios() -> list[str]:
    return sorted(p.stem for p in BUNDLED_DIR.glob("*.toml"))


def load_scenario(ref: str) -> Scenario:
    """A preset name, a bundled scenario name, or a path to a TOML file."""
    m = re.fullmatch(r"setup([123])(?:-(\d+))?", ref)
    if m:
        number = int(m.group(1))
        if number != 3 and m.group(2):
            raise ScenarioError(f"preset {ref}", "name", f"setup{number} takes no size")
        size = int(m.group(2)) if m.group(2) else None
        if size is not None and not 5 <= size <= 4096:
            raise ScenarioError(f"preset {ref}", "size", "expected a size from 5 to 4096")
        return paper_setup(number, size)
    path = Path(ref)
    if not path.exists() and (BUNDLED_DIR / f"{ref}.toml").exists():
        path = BUNDLED_DIR / f"{ref}.toml"
    if not path.exists():
        raise ScenarioError(
            ref,
            "scenario",
            f"no such file or preset; presets: {PRESET_HELP}; bundled: {', '.join(bundled_scenarios())}",
        )
    return parse_scenario_text(path.read_text(encoding="utf-8", errors="replace"), str(path))


def parse_scenario_text(text: str, source: str = "<string>", kind: str | None = None, name: str | None = None):
    """The scenario of the world kind the file names (`kind = ...`; the default kind's when it names
    none), or of `kind` (the file may then leave it out), named `name` (default: the file's stem)
    unless the file says.  Each kind parses its own section (world_server.WORLD_KINDS)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(source, "TOML", f"not valid TOML ({exc})") from None
    try:
        spec = world_kind(kind or data.get("kind", world_kind().name))
    except UnknownPart as exc:
        raise ScenarioError(source, "kind", str(exc)) from None
    controllers = CONTROLLERS.where("world", spec.name)  # what its groups may name ("module:Class" too)
    return resolve(spec.parse)(data, text, source, name or Path(source).stem, controllers)


def parse_arena_text(text: str, source: str = "<string>", default_name: str = "arena") -> ArenaScenario:
    """An arena scenario from TOML text (kind = "arena" may be left out)."""
    return parse_scenario_text(text, source, "arena", default_name)


def scenario_schema() -> dict:
    """The JSON Schema of a scenario file: one of the world kinds' schemas (each kind's `schema`,
    given that kind's controllers from the registry)."""
    from world_server import WORLD_KINDS

    kinds = [resolve(k.schema)({c.name: c for c in CONTROLLERS if c.world == k.name})
             for k in WORLD_KINDS if k.schema is not None]  # fmt: skip
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", "title": "swarm scenario file",
            "description": "A scenario of any world kind (`kind`; a file that names none is the default kind's).",
            "oneOf": kinds}  # fmt: skip
