"""A sweep file: which scenarios, which values of which parameters, which seeds, which metrics.

Everything is checked here, in one line per mistake (ScenarioError), before any run: the file's own
keys, and every condition's scenario, built as its runs will build it, so a bad grid key or value is
refused by the scenario parser exactly as it would be in a scenario file.
"""

from __future__ import annotations

import itertools
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from swarm.core.errors import ScenarioError
from swarm.core.registry import resolve
from swarm.core.tables import no_unknown
from swarm.sweeps.jobs import KIND_SETTINGS, Condition, build
from world_server import kind_of

# Top-level keys that set a run rather than a scenario's table: a list is an axis, a scalar a fixed value.
SETTINGS = ("controller", "agents", *sorted({k for keys in KIND_SETTINGS.values() for k in keys}))
TOP = {"scenarios", "seeds", "metrics", "grid", *SETTINGS}
MAX_SEED = 2**63


@dataclass(frozen=True)
class SweepSpec:
    """A parsed sweep file: its axes in column order (grid keys first, then the run settings that are lists)."""

    name: str
    source: str
    scenarios: tuple[str, ...]
    grid: tuple[tuple[str, tuple[Any, ...]], ...]
    settings: tuple[tuple[str, tuple[Any, ...]], ...]
    seeds: tuple[int, ...]
    metrics: tuple[str, ...]

    @property
    def axes(self) -> list[str]:
        """The columns that tell conditions apart besides the scenario: every grid key, each listed setting."""
        return [k for k, _ in self.grid] + [k for k, v in self.settings if len(v) > 1 or k == "agents"]

    def conditions(self) -> list[Condition]:
        """Every scenario with every combination of the grid's and the settings' values, checked."""
        out, kinds = [], set()
        for scenario in self.scenarios:
            for grid in itertools.product(*(v for _, v in self.grid)):
                for values in itertools.product(*(v for _, v in self.settings)):
                    settings = tuple(zip((k for k, _ in self.settings), values, strict=True))
                    condition = Condition(scenario, tuple(zip((k for k, _ in self.grid), grid, strict=True)), settings)
                    built = _built(condition, self.seeds[0], self.source)
                    kinds.add(kind_of(built).name)
                    out.append(condition.with_setting("agents", built.agents))  # the scenario's own where unset
        taken = {"controller", "agents"} | {k for kind in kinds for k in KIND_SETTINGS.get(kind, ())}
        for key, _ in self.settings:
            if key not in taken:
                raise ScenarioError(self.source, key, f"no scenario of this sweep takes it ({', '.join(sorted(kinds))} "
                                    f"scenarios take {', '.join(sorted(taken))})")  # fmt: skip
        return out


def _built(condition: Condition, seed: int, source: str) -> Any:
    """The condition's scenario; what its overrides refuse is the sweep file's mistake, named so."""
    try:
        return build(condition, seed)[0]
    except ScenarioError as exc:
        if exc.source != "command line":
            raise
        raise ScenarioError(f"{source} ({condition.scenario})", exc.where, exc.problem) from None


def read_spec(path_or_dict: str | Path | Mapping[str, Any], name: str | None = None) -> SweepSpec:
    """A sweep file (TOML), or its tables as a dict, checked (ScenarioError in one line)."""
    if isinstance(path_or_dict, Mapping):
        data, source = dict(path_or_dict), "<sweep>"
        name = name or "sweep"
    else:
        path = Path(path_or_dict)
        source, name = str(path), name or path.stem
        try:
            data = tomllib.loads(path.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise ScenarioError(source, "sweep file", "no such file") from None
        except tomllib.TOMLDecodeError as exc:
            raise ScenarioError(source, "TOML", f"not valid TOML ({exc})") from None
    no_unknown(data, TOP, source, "top level")
    grid = data.get("grid", {})
    if not isinstance(grid, dict):
        raise ScenarioError(source, "grid", 'expected a [grid] table of "dotted.key" = [values]')
    return SweepSpec(
        name=name,
        source=source,
        scenarios=_scenarios(data, source),
        grid=tuple((key, _values(value, source, f"grid.{key}")) for key, value in grid.items()),
        settings=_settings(data, source),
        seeds=_seeds(data.get("seeds", [0]), source),
        metrics=_metrics(data.get("metrics"), source),
    )


def _values(value: Any, source: str, where: str) -> tuple[Any, ...]:
    """An axis's values: a list, or one value."""
    values = tuple(value) if isinstance(value, list) else (value,)
    if not values:
        raise ScenarioError(source, where, "expected at least one value")
    if len(set(map(repr, values))) != len(values):
        raise ScenarioError(source, where, f"a value comes twice in {list(values)}")
    return values


def _scenarios(data: dict, source: str) -> tuple[str, ...]:
    refs = _values(data.get("scenarios", []), source, "scenarios")
    if not all(isinstance(r, str) for r in refs):
        raise ScenarioError(source, "scenarios", "expected names of presets, bundled scenarios or files")
    base = Path(source).parent if source != "<sweep>" else Path()
    # a file named relative to the sweep file, where it is there
    return tuple(str(base / r) if r.endswith(".toml") and (base / r).exists() else r for r in refs)


def _settings(data: dict, source: str) -> tuple[tuple[str, tuple[Any, ...]], ...]:
    settings = [(key, _values(data[key], source, key)) for key in SETTINGS if key in data]
    if "agents" not in data:
        settings.append(("agents", (None,)))  # the scenario's own count (filled in by `conditions`)
    return tuple(settings)


def _seeds(value: Any, source: str) -> tuple[int, ...]:
    if isinstance(value, dict):
        no_unknown(value, {"first", "count"}, source, "seeds")
        first, count = value.get("first", 0), value.get("count")
        if not isinstance(first, int) or not isinstance(count, int) or count < 1:
            raise ScenarioError(source, "seeds", "expected { first = N, count = K } with whole numbers, K >= 1")
        value = list(range(first, first + count))
    seeds = _values(value, source, "seeds")
    if not all(isinstance(s, int) and not isinstance(s, bool) and 0 <= s < MAX_SEED for s in seeds):
        raise ScenarioError(source, "seeds", "expected whole numbers from 0 to 2**63-1")
    return seeds


def _metrics(value: Any, source: str) -> tuple[str, ...]:
    if value is None:
        raise ScenarioError(source, "metrics", 'missing: name the summary keys to collect, e.g. ["reached"]')
    metrics = _values(value, source, "metrics")
    for m in metrics:
        if not isinstance(m, str) or not m:
            raise ScenarioError(source, "metrics", "expected names of summary keys or module:function")
        if ":" in m:
            try:
                if not callable(resolve(m)):
                    raise TypeError("not callable")
            except (ImportError, AttributeError, TypeError) as exc:
                raise ScenarioError(source, "metrics", f"cannot use {m!r}: {exc}") from None
    return metrics
