"""A sweep's runs: a condition's scenario, built from the scenario's own tables with the grid's values
set in them, and one run of it in process, as `swarm run` would run it; its row of metrics.

A job carries names and values only (no scenario object), so it pickles cheaply into a worker, which
builds the scenario again from the same tables: the run is the one a scenario file with those values
would give, whoever runs it.
"""

from __future__ import annotations

import argparse
import copy
import math
import time
from dataclasses import dataclass, replace
from typing import Any

from swarm.core.errors import ScenarioError
from swarm.core.registry import resolve

# The run settings each world kind takes besides controller, agents and seed (with_overrides, or its run).
KIND_SETTINGS = {
    "arena": ("max_ticks", "noise", "on_controller_error"),
    "grid": ("until", "max_iterations", "physics", "body_diameter"),
}
RUN_DEFAULTS = {"until": "foraged", "max_iterations": 1_000_000}


@dataclass(frozen=True)
class Condition:
    """One scenario with one value of each axis: (dotted key, value) pairs of its tables, and run settings."""

    scenario: str
    grid: tuple[tuple[str, Any], ...]
    settings: tuple[tuple[str, Any], ...]

    def with_setting(self, key: str, value: Any) -> Condition:
        return replace(self, settings=tuple((k, value if k == key else v) for k, v in self.settings))


@dataclass(frozen=True)
class Job:
    """A condition's run with one seed, and the metrics its row keeps."""

    condition: Condition
    seed: int
    metrics: tuple[str, ...]


def assign(data: dict, key: str, value: Any, source: str) -> None:
    """Set the dotted `key` of a scenario's tables to `value`, making the tables on the way.  A part
    naming a user's controller ("pkg.mod:Class.speed") keeps its dots; a number indexes an array of
    tables from 1 ("group.1.count"), as the parser's messages count them."""
    head, colon, tail = key.partition(":")
    parts = [f"{head}:{tail.split('.')[0]}", *tail.split(".")[1:]] if colon else key.split(".")
    where: Any = data
    for i, part in enumerate(parts):
        last = i == len(parts) - 1
        if isinstance(where, list):
            if not part.isdigit() or not 1 <= int(part) <= len(where):
                raise ScenarioError(source, key, f"{part!r}: expected a number from 1 to {len(where)}")
            if last:
                where[int(part) - 1] = value
            else:
                where = where[int(part) - 1]
        elif isinstance(where, dict):
            if last:
                where[part] = value
            else:
                where = where.setdefault(part, {})
        else:
            raise ScenarioError(source, key, f"{'.'.join(parts[:i])} is a value, not a table")


def build(condition: Condition, seed: int) -> tuple[Any, argparse.Namespace]:
    """The condition's scenario with `seed`, checked as a file's, and the run options of its kind."""
    from swarm.scenario import parse_scenario_data, scenario_tables
    from world_server import kind_of

    data, text, source = scenario_tables(condition.scenario)
    data = copy.deepcopy(data)
    for key, value in condition.grid:
        assign(data, key, value, source)
    scenario = parse_scenario_data(data, text, source)
    kind = kind_of(scenario)
    settings = {k: v for k, v in dict(condition.settings).items() if k not in _others(kind.name)}
    args = argparse.Namespace(**{k: None for keys in KIND_SETTINGS.values() for k in keys})
    args.__dict__.update(RUN_DEFAULTS | {k: v for k, v in settings.items() if v is not None})
    args.__dict__.update(controller=settings.get("controller"), start=None, goal=None, record=None, json=True)
    common = {"agents": settings.get("agents"), "controller": settings.get("controller"), "seed": seed}
    try:
        return resolve(kind.overrides)(scenario, args, common), args
    except ValueError as exc:  # a registry's unknown controller
        if isinstance(exc, ScenarioError):
            raise
        raise ScenarioError(source, "controller", str(exc)) from None


def _others(kind: str) -> set[str]:
    """The settings only other world kinds take."""
    return {k for name, keys in KIND_SETTINGS.items() if name != kind for k in keys} - set(KIND_SETTINGS.get(kind, ()))


def run_job(job: Job) -> dict:
    """One run in process; its row: the metrics and the wall time."""
    from world_server import kind_of

    scenario, args = build(job.condition, job.seed)
    start = time.perf_counter()
    summary = resolve(kind_of(scenario).run)(scenario, args, None)
    wall = time.perf_counter() - start
    return {**{m: metric(summary, m) for m in job.metrics}, "wall_s": round(wall, 4)}


def metric(summary: dict, name: str) -> float:
    """A summary's value of `name`: its top-level key, else the robots' mean of their key ("distance"),
    else a "module:function" of the summary (nan: no value, as a path ratio without a goal)."""
    if ":" in name:
        try:
            value = resolve(name)(summary)
        except Exception as exc:  # whatever a user's function raises: one line naming it
            raise ScenarioError("metrics", name, f"raised {type(exc).__name__}: {exc}") from None
        return _number(value, name)
    if name in summary:
        return _number(summary[name], name)
    values = [_number(r[name], name) for r in summary.get("robots", ()) if name in r]
    values = [v for v in values if not math.isnan(v)]
    return float(sum(values) / len(values)) if values else math.nan


def _number(value: Any, name: str) -> float:
    if value is None:
        return math.nan
    if isinstance(value, bool | int | float):
        return float(value)
    raise ScenarioError("metrics", name, f"expected a number in the run's summary, got a {type(value).__name__}")


def check_metrics(job: Job) -> None:
    """Run the job for one tick and refuse, in one line, a metric its summary does not have."""
    from world_server import kind_of

    scenario, args = build(job.condition, job.seed)
    if kind_of(scenario).name == "arena":
        scenario = scenario.with_overrides(max_ticks=1)
    args.max_iterations = 1
    summary = resolve(kind_of(scenario).run)(scenario, args, None)
    robots = {k for r in summary.get("robots", ()) for k in r}
    for m in job.metrics:
        if ":" not in m and m not in summary and m not in robots:
            scalars = ", ".join(sorted(k for k, v in summary.items() if isinstance(v, bool | int | float | None)))
            theirs = ", ".join(sorted(robots)) or "none"
            raise ScenarioError(job.condition.scenario, "metrics", f"no {m!r} in its summary; it has {scalars}, "
                                f"and the robots' {theirs}")  # fmt: skip
        metric(summary, m)


def warm_up(*jobs: Job) -> None:
    """Compile (or load) the kernels of each job's world kind in a worker, so no run's wall time pays it."""
    from world_server import kind_of

    warmed = set()
    for job in jobs:
        scenario, _ = build(job.condition, job.seed)
        if kind_of(scenario).name not in warmed:
            warmed.add(kind_of(scenario).name)
            resolve(kind_of(scenario).warm_up)(scenario)
