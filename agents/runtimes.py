"""The agent runtime of a controller's world kind, for `swarm agent` and the launcher."""

from __future__ import annotations

from agents.controllers import CONTROLLERS
from agents.runtime import AgentRuntime
from swarm.core.bus import DEFAULT_ENDPOINT
from swarm.core.registry import resolve
from world_server import WORLD_KINDS


def make_runtime(run_id: str, controller: str, connect: str = DEFAULT_ENDPOINT, count: int = 1,
                 **kw) -> AgentRuntime:  # fmt: skip
    """The runtime its world kind's entry names (world_server.WORLD_KINDS)."""
    runtime = resolve(WORLD_KINDS[CONTROLLERS[controller].world].runtime)
    return runtime(run_id, controller, connect, count, **kw)
