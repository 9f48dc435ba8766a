"""Controllers for `swarm bench recording`: wander, with a record() of a chosen size beside its own.

They are named on the command line as a user's controller is (`--controller
swarm.bench.recording.payload:View64`), so the world records their record() by shape: each agent
process sends it to the world on its record key, the numbers every tick and the image every tenth
(world_server/arena/face/wire.py), the path whose cost the bench measures.
`view` is a CELLS x CELLS float32 image (an occupancy grid, a neural field) that changes every tick.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from agents.controllers.wander.controller import WanderController


class View0(WanderController):
    """Wander's own record() alone: the turn it is in, one scalar."""

    CELLS = 0

    def reset(self, seed: int, agent: int, params: dict[str, Any]) -> None:
        super().reset(seed, agent, params)
        side = np.arange(self.CELLS, dtype=np.float32)
        self.base = np.sin(side[:, None] * 0.3 + agent) * np.cos(side[None, :] * 0.2)

    def record(self) -> dict[str, np.ndarray]:
        out = super().record()
        if self.CELLS:
            out["view"] = np.roll(self.base, self.tick, axis=1)
        return out


class View16(View0):
    """A 16 x 16 image a tick (1 KB)."""

    CELLS = 16


class View64(View0):
    """A 64 x 64 image a tick (16 KB)."""

    CELLS = 64


class View128(View0):
    """A 128 x 128 image a tick (64 KB)."""

    CELLS = 128
