"""The one contract every world kind keeps (DESIGN: two kinds behind one contract).

The engines, the world process, persistence and the recorder need exactly this
of a world; `GridWorld` and `ArenaWorld` both keep it, and
`swarm.engines.stepper.step_world` runs either one from it alone (tests/test_contract.py
runs the grid that way and gets the compiled engine's run, tick for tick).
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class World(Protocol):
    kind: str  # "grid" | "arena"
    n: int  # agents (slots)
    tick: int  # ticks resolved so far

    def perceive_all(self) -> Any:
        """Every agent's perception of the start-of-tick world, as this kind
        batches it (grid: (pi, pf) arrays; arena: one dict of readings per robot)."""

    def apply_all(self, actions: np.ndarray) -> None:
        """Validate and apply every agent's action, resolve one tick, tick += 1."""

    def done(self) -> bool:
        """The world has reached its own end (the grid: its `until` rule; the arena: its last tick or its
        metabolism's rule).  A runner may end a run sooner: the arena's goals (swarm.engines.goals)."""

    def snapshot(self) -> dict[str, np.ndarray]:
        """The state a restarted world resumes from (arrays only)."""

    def restore(self, state: dict[str, np.ndarray]) -> None: ...
