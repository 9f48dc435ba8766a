"""Scenarios: a preset, a bundled name or a TOML file, read into its world kind's scenario.

`kind = "grid"` (the default: the c-marking paper's worlds, world_server/grid/scenario.py)
or `kind = "arena"` (world_server/arena/scenario.py).  Every error is a
ScenarioError naming the file and the field.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path
from typing import TYPE_CHECKING

from agents.controllers import CONTROLLERS
from swarm.core.errors import ScenarioError
from world_server.grid.scenario import Scenario, paper_setup, parse_grid

if TYPE_CHECKING:
    from world_server.arena.scenario import ArenaScenario

WORLD_KINDS = ("grid", "arena")


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


def is_arena(scenario) -> bool:
    return getattr(scenario, "kind", "grid") == "arena"


def parse_scenario_text(text: str, source: str = "<string>"):
    """A grid Scenario, or an ArenaScenario when the file says kind = "arena"."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(source, "TOML", f"not valid TOML ({exc})") from None
    kind = data.get("kind", "grid")
    if kind not in WORLD_KINDS:
        raise ScenarioError(source, "kind", f"unknown world kind {kind!r}; expected one of {', '.join(WORLD_KINDS)}")
    if kind == "arena":
        return parse_arena_tables(data, source, Path(source).stem)
    data.pop("kind", None)
    return parse_grid(data, text, source)


def arena_controllers() -> dict:
    """The registry's arena controllers, by name: what an arena scenario's groups may name."""
    return {c.name: c for c in CONTROLLERS if c.world == "arena"}


def parse_arena_text(text: str, source: str = "<string>", default_name: str = "arena") -> ArenaScenario:
    """An arena scenario from TOML text (kind = "arena" may be left out)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(source, "TOML", f"not valid TOML ({exc})") from None
    return parse_arena_tables(data, source, default_name)


def parse_arena_tables(data: dict, source: str, default_name: str) -> ArenaScenario:
    # Imported here, not above: the arena's sensors load numba, and `swarm agent` (an agent
    # process, which reads no scenario) must start without it to stay under 80 MB.
    from world_server.arena.scenario import parse_arena

    return parse_arena(data, source, default_name, arena_controllers())
