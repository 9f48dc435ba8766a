"""One lock-step loop for any world kind, through world_server.contract.World.

Every agent perceives the start-of-tick world, `decide` turns the batch of
perceptions into the batch of actions, and the world resolves the tick.  The
arena's in-process engine runs on it; the grid's compiled engine (swarm.engines.grid)
is the same loop compiled whole, and tests/test_contract.py checks that the grid
run through this one gives its run tick for tick.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from world_server.contract import World


def step_world(world: World, decide: Callable[[Any, int], np.ndarray], n: int,
               after: Callable[[], None] | None = None, done: Callable[[], bool] | None = None) -> int:  # fmt: skip
    """Up to n ticks (fewer once `done()`, by default `world.done()`); `after` runs after each tick.
    Returns ticks run."""
    done = done or world.done
    ran = 0
    while ran < n and not done():
        world.apply_all(decide(world.perceive_all(), world.tick))
        if after is not None:
            after()
        ran += 1
    return ran
