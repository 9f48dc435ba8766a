"""Scenarios: a preset, a bundled name or a TOML file, read into its world kind's scenario.

A file's `kind` names its world kind (world_server.WORLD_KINDS; a file without one is of the
default kind, the grid), and the kind parses the rest (world_server/<kind>/scenario.py).  Every
error is a ScenarioError naming the file and the field.
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import asdict, replace
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
    preset = _preset(ref)
    if preset is not None:
        return preset
    path = scenario_path(ref)
    return parse_scenario_text(path.read_text(encoding="utf-8", errors="replace"), str(path))


def _preset(ref: str) -> Scenario | None:
    """The paper's setup `ref` names (None: `ref` names no preset)."""
    m = re.fullmatch(r"setup([123])(?:-(\d+))?", ref)
    if not m:
        return None
    number = int(m.group(1))
    if number != 3 and m.group(2):
        raise ScenarioError(f"preset {ref}", "name", f"setup{number} takes no size")
    size = int(m.group(2)) if m.group(2) else None
    if size is not None and not 5 <= size <= 4096:
        raise ScenarioError(f"preset {ref}", "size", "expected a size from 5 to 4096")
    # a preset may be run with any grid controller the registry knows (a user's "module:NAME" too)
    return replace(paper_setup(number, size), known_controllers=CONTROLLERS.where("world", "grid"))


def scenario_path(ref: str) -> Path:
    """The file of a bundled name or a path (ScenarioError naming the choices when there is none)."""
    path = Path(ref)
    if not path.exists() and (BUNDLED_DIR / f"{ref}.toml").exists():
        path = BUNDLED_DIR / f"{ref}.toml"
    if not path.exists():
        raise ScenarioError(
            ref,
            "scenario",
            f"no such file or preset; presets: {PRESET_HELP}; bundled: {', '.join(bundled_scenarios())}",
        )
    return path


def scenario_tables(ref: str) -> tuple[dict, str, str]:
    """(tables, text, source) of a scenario as a file would give them, so that a program can change a
    value and parse it again (parse_scenario_data) with every check a file gets.  A preset's tables
    are those of a file that says what the preset is (its generator, counts and seed)."""
    preset = _preset(ref)
    if preset is not None:
        assert preset.generator is not None
        data = {"name": preset.name, "seed": preset.seed, "agents": preset.agents, "controller": preset.controller,
                "q_max": preset.q_max, "quantity": preset.quantity, "generator": asdict(preset.generator)}  # fmt: skip
        return data, "", preset.source
    path = scenario_path(ref)
    text = path.read_text(encoding="utf-8", errors="replace")
    return _toml(text, str(path)), text, str(path)


def _toml(text: str, source: str) -> dict:
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(source, "TOML", f"not valid TOML ({exc})") from None


def parse_scenario_text(text: str, source: str = "<string>", kind: str | None = None, name: str | None = None):
    """The scenario of the world kind the file names (`kind = ...`; the default kind's when it names
    none), or of `kind` (the file may then leave it out), named `name` (default: the file's stem)
    unless the file says.  Each kind parses its own section (world_server.WORLD_KINDS)."""
    return parse_scenario_data(_toml(text, source), text, source, kind, name)


def parse_scenario_data(data: dict, text: str = "", source: str = "<string>", kind: str | None = None,
                        name: str | None = None):  # fmt: skip
    """The scenario of a file's tables `data` (parse_scenario_text; `text` only points at map lines)."""
    try:
        spec = world_kind(kind or data.get("kind", world_kind().name))
    except UnknownPart as exc:
        raise ScenarioError(source, "kind", str(exc)) from None
    controllers = CONTROLLERS.where("world", spec.name)  # what its groups may name ("module:Class" too)
    return resolve(spec.parse)(data, text, source, name or Path(source).stem, controllers)


def parse_arena_text(text: str, source: str = "<string>", default_name: str = "arena") -> ArenaScenario:
    """An arena scenario from TOML text (kind = "arena" may be left out)."""
    return parse_scenario_text(text, source, "arena", default_name)


def scenario_schema(installed: bool = True) -> dict:
    """The JSON Schema of a scenario file: one of the world kinds' schemas (each kind's `schema`,
    given that kind's controllers from the registry; with `installed` False, only the package's own
    controllers and sensors, not those of installed packages' entry points: the schema the package
    carries)."""
    from world_server import WORLD_KINDS

    def mine(c) -> bool:
        return installed or c.name not in CONTROLLERS.installed

    every = CONTROLLERS if installed else CONTROLLERS.including(())  # installed ones: not even imported
    kinds = [resolve(k.schema)({c.name: c for c in every if c.world == k.name and mine(c)}, installed)
             for k in WORLD_KINDS if k.schema is not None]  # fmt: skip
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", "title": "swarm scenario file",
            "description": "A scenario of any world kind (`kind`; a file that names none is the default kind's).",
            "oneOf": kinds}  # fmt: skip
