"""The world process (`swarm world`): the server of the scenario's world kind, lent what lives above
the worlds (its recorder, the arena's goals and L_o), run until the run ends."""

from __future__ import annotations

import functools
import json
import sys
import time

from world_server.arena.server import ArenaKind
from world_server.grid.server import GridKind
from world_server.server import RunnerServices, WorldServer


def services_for(scenario) -> RunnerServices:
    if getattr(scenario, "kind", "grid") == "arena":
        from swarm.engines.goals import ArenaGoals
        from swarm.recording.arena import open_for_server

        return RunnerServices(open_recorder=open_for_server, goals=ArenaGoals)
    from swarm.recording.grid import open_for_server

    return RunnerServices(open_recorder=open_for_server)


def make_server(scenario, run_id: str, **kw) -> WorldServer:
    """The world server holding the scenario's world kind, with this runner's services."""
    kw.setdefault("services", services_for(scenario))
    kind = ArenaKind if getattr(scenario, "kind", "grid") == "arena" else GridKind
    return WorldServer(kind, scenario, run_id, **kw)


def serve(scenario, run_id: str, summary_file: str | None = None, linger: float = 0.0, quiet: bool = False,
          **kw) -> dict:  # fmt: skip
    server = make_server(scenario, run_id, **kw)
    log = (lambda *_: None) if quiet else functools.partial(print, file=sys.stderr, flush=True)
    try:
        log(f"swarm world: run {run_id!r}, {scenario.name} (seed {scenario.seed}, {scenario.controller}): "
            f"{server.start_with} agents start it, up to {scenario.agents} may join")  # fmt: skip
        summary = server.run()
        log(f"swarm world: run {run_id!r} {'finished' if summary['finished'] else 'stopped'} after "
            f"{summary['iterations']} ticks; recording: {summary['recording']}")  # fmt: skip
        if linger > 0:
            log(f"swarm world: serving the final state for {linger:g} s")
        server.stop_agents("finished" if summary["finished"] else "stopped")
        if summary_file:
            with open(summary_file, "w") as f:
                json.dump(summary, f)
        end = time.monotonic() + linger
        server.linger(lambda: time.monotonic() >= end)
    finally:
        server.close()
    return summary
