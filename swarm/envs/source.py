"""Which arena scenario an env runs: a bundled name, a file or a loaded ArenaScenario."""

from __future__ import annotations

from typing import Any

from world_server.arena.scenario import ArenaScenario


def arena_scenario(scenario: str | ArenaScenario, max_ticks: int | None = None, **overrides: Any) -> ArenaScenario:
    """The scenario with its overrides (ArenaScenario.with_overrides: agents, noise, controller, ...); an
    env needs an arena of bodies and sensors, so any other world kind is refused in one line."""
    if not isinstance(scenario, ArenaScenario):
        from swarm.scenario import load_scenario

        loaded = load_scenario(str(scenario))
        if not isinstance(loaded, ArenaScenario):
            kind = getattr(loaded, "kind", type(loaded).__name__)
            raise ValueError(f"{scenario}: a {kind} scenario; swarm.envs runs arena scenarios only")
        scenario = loaded
    if max_ticks is not None or overrides:
        scenario = scenario.with_overrides(max_ticks=max_ticks, **overrides)
    return scenario
