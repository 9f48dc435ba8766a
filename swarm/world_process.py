"""The world process (`swarm world`): the server of the scenario's world kind, lent what lives above
the worlds (its recorder, the arena's goals and L_o), run until the run ends."""

from __future__ import annotations

import functools
import json
import sys
import time

from swarm.core.registry import resolve
from world_server import kind_of
from world_server.server import RunnerServices, WorldServer


def services_for(scenario) -> RunnerServices:
    """What the world process lends the server of the scenario's world kind: its recorder, its
    goals bookkeeping (world_server.WORLD_KINDS)."""
    kind = kind_of(scenario)
    return RunnerServices(open_recorder=kind.open_recorder and resolve(kind.open_recorder),
                          goals=kind.goals and resolve(kind.goals))  # fmt: skip


def make_server(scenario, run_id: str, **kw) -> WorldServer:
    """The world server holding the scenario's world kind, with this runner's services."""
    kw.setdefault("services", services_for(scenario))
    return WorldServer(resolve(kind_of(scenario).server), scenario, run_id, **kw)


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
