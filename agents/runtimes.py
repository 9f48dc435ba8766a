"""The agent runtime of a controller's family, for `swarm agent` and the launcher."""

from __future__ import annotations

from agents.arena_runtime import ArenaAgentRuntime
from agents.controllers import CONTROLLERS
from agents.grid_runtime import GridAgentRuntime
from agents.runtime import AgentRuntime
from swarm.core.bus import DEFAULT_ENDPOINT


def make_runtime(run_id: str, controller: str, connect: str = DEFAULT_ENDPOINT, count: int = 1,
                 **kw) -> AgentRuntime:  # fmt: skip
    """The runtime of the controller's family."""
    if CONTROLLERS[controller].world == "arena":
        return ArenaAgentRuntime(run_id, controller, connect, count, **kw)
    return GridAgentRuntime(run_id, controller, connect, count, **kw)
