"""The arena's checks and limits on wheel speeds, compiled.

Every tick the world asks of each robot's action whether it may be acted on
(finite, within the wheels' limit, a known act) and scales accepted wheel
speeds down to the model's forward-speed and turn-rate limits.  As numpy on
arrays of a few robots these were some 25 small calls a tick; each loop here
is written in the order of operations of the numpy expressions it replaced,
so the numbers are the same to the bit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

ACTION_LEN = 2  # left and right wheel speeds, m/s
ACTION_WIDTH = 3  # ... and a consummatory act (world_server.arena.metabolism.ACTS), optional: 0 when left out
REJECT_REASONS = ("not finite", "over the wheel limit", "wrong shape", "unknown act")
NOT_FINITE, OVER_LIMIT, UNKNOWN_ACT = (REJECT_REASONS.index(r) for r in ("not finite", "over the wheel limit",
                                                                          "unknown act"))  # fmt: skip


@njit(cache=True)
def refusals(actions: np.ndarray, max_wheel: np.ndarray, robots: np.ndarray, acts: int, with_acts: bool,
             out: np.ndarray) -> None:  # fmt: skip
    """Per row of (k, 2) wheel speeds, or (k, 3) with an act, of these robots: why it cannot be acted on
    (NOT_FINITE, OVER_LIMIT, UNKNOWN_ACT), or -1.  An act is known when it is a whole number in [0, acts),
    and only 0 without a metabolism (`with_acts` False)."""
    width = actions.shape[1]
    for r in range(actions.shape[0]):
        finite = True
        for j in range(width):
            if not math.isfinite(actions[r, j]):
                finite = False
        why = -1 if finite else NOT_FINITE
        if finite:
            limit = max_wheel[robots[r]] * (1 + 1e-9)
            for j in range(ACTION_LEN):
                if abs(actions[r, j]) > limit:
                    why = OVER_LIMIT
        if width == ACTION_WIDTH:
            act = actions[r, width - 1] if finite else 0.0
            known = act == math.floor(act) and act >= 0 and act < acts  # a whole number: np.round's test
            if not with_acts:
                known = known and act == 0
            if why < 0 and not known:
                why = UNKNOWN_ACT
        out[r] = why


@njit(cache=True)
def limited(wheels: np.ndarray, axle: np.ndarray, max_speed: np.ndarray, max_turn: np.ndarray,
            out: np.ndarray) -> None:  # fmt: skip
    """Wheel speeds (n, 2) scaled down so that v = (l + r) / 2 and w = (r - l) / axle keep within each
    model's forward-speed and turn-rate limits, into `out`."""
    for i in range(wheels.shape[0]):
        v = (wheels[i, 0] + wheels[i, 1]) / 2
        w = (wheels[i, 1] - wheels[i, 0]) / axle[i]
        sv = max_speed[i] / max(abs(v), 1e-12) if abs(v) > max_speed[i] else 1.0
        sw = max_turn[i] / max(abs(w), 1e-12) if abs(w) > max_turn[i] else 1.0
        v, w = v * sv, w * sw
        out[i, 0] = v - w * axle[i] / 2
        out[i, 1] = v + w * axle[i] / 2
