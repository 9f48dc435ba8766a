"""The face every arena controller shows both engines.

An arena controller is an object (it carries maps, fields or neurons):
`reset(seed, agent, params)` once, then `step(perception) -> (left, right)`
wheel speeds in m/s each tick.  It sees only its robot's sensors (the
perception dict) and what its paper gives the robot beforehand (`params`:
the map it is given, its goal or route, its body's limits).
`snapshot()` / `restore()` make a resumed run bit-equal; `record()` returns
what a reviewer should see.  The in-process engine holds N of them; an agent
process holds K.
"""

from __future__ import annotations

import importlib
from typing import Any, Protocol

import numpy as np

REGISTRY = {
    "carrot": "agents.controllers.carrot:CarrotController",
    "wander": "agents.controllers.wander:WanderController",
}
ARENA_CONTROLLERS = tuple(REGISTRY)
# What a controller needs its robot to sense (checked when a scenario is loaded).
REQUIRES = {"carrot": ("position", "compass"), "wander": ()}


class ArenaController(Protocol):
    def reset(self, seed: int, agent: int, params: dict[str, Any]) -> None: ...

    def step(self, perception: dict[str, np.ndarray]) -> np.ndarray: ...

    def snapshot(self) -> dict[str, Any]: ...

    def restore(self, state: dict[str, Any]) -> None: ...

    def record(self) -> dict[str, np.ndarray]: ...


def make_controller(name: str) -> ArenaController:
    module, cls = REGISTRY[name].split(":")
    return getattr(importlib.import_module(module), cls)()
