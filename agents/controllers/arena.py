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
    "fingerprint": "agents.controllers.fingerprint:FingerprintController",
}
ARENA_CONTROLLERS = tuple(REGISTRY)
# Each controller's own scenario table, checked when a scenario is loaded (a callable raising ValueError).
TABLES = {
    "carrot": "agents.controllers.carrot:CarrotParams.from_table",
    "wander": "agents.controllers.wander.controller:WanderParams.from_table",
    "fingerprint": "agents.controllers.fingerprint.controller:check_table",
}
# What a controller needs its robot to sense (checked when a scenario is loaded).
REQUIRES = {"carrot": ("position", "compass"), "wander": (), "fingerprint": ("camera", "laser", "odometry", "compass")}


class ArenaController(Protocol):
    def reset(self, seed: int, agent: int, params: dict[str, Any]) -> None: ...

    def step(self, perception: dict[str, np.ndarray]) -> np.ndarray: ...

    def snapshot(self) -> dict[str, Any]: ...

    def restore(self, state: dict[str, Any]) -> None: ...

    def record(self) -> dict[str, np.ndarray]: ...


def check_table(name: str, table: dict[str, Any]) -> None:
    """Raise ValueError (one line, naming the field) if `table` is not a valid [name] table."""
    module, attr = TABLES[name].split(":")
    target: Any = importlib.import_module(module)
    for part in attr.split("."):
        target = getattr(target, part)
    target(table)


def make_controller(name: str) -> ArenaController:
    module, cls = REGISTRY[name].split(":")
    return getattr(importlib.import_module(module), cls)()
