"""Follow the carrot (Barton 2001), as Appendix B of Billing et al. (2015) states it.

The carrot p_c is the path point nearest to the look-ahead point p_look, k_look
straight ahead of the robot; the steering angle is phi = k_fic * (phi_c - phi_h),
phi_c the bearing of the carrot, phi_h the heading.  The paper leaves three
things open; our choices (docs/arena.md):
- the search for p_c runs forward from the last carrot to the first local
  minimum of the distance (at most `window` points on), so the carrot never
  jumps back to an earlier stretch, nor across a fold to a later stretch that
  passes close by (a route into a room and out again);
- phi is the turn rate (rad/s) and the forward speed is speed * max(0, cos(error)),
  so the robot turns on the spot when the carrot is behind it;
- the wheel speeds keep their ratio when one would exceed the wheel limit.

PaperCarrotFollower is Appendix B literally ([carrot] variant = "paper"): the
carrot is the nearest point of the whole path (eq. 18, no window: it may jump
back or across a fold), and the robot drives at its cruise speed while it
steers, its turn rate clipped so that neither wheel exceeds the wheel limit.
"""

from __future__ import annotations

import math

import numpy as np


def wrap(angle: float) -> float:
    return (angle + math.pi) % (2 * math.pi) - math.pi


class CarrotFollower:
    def __init__(self, path: np.ndarray, k_fic: float, k_look: float, speed: float, window: int):
        self.path = np.asarray(path, np.float64).reshape(-1, 2)
        self.k_fic, self.k_look, self.speed, self.window = k_fic, k_look, speed, window
        self.index = 0

    def carrot(self, x: float, y: float, heading: float) -> np.ndarray:
        look = np.array([x + self.k_look * math.cos(heading), y + self.k_look * math.sin(heading)])
        ahead = self.path[self.index : self.index + self.window]
        d = ((ahead - look) ** 2).sum(axis=1)
        rising = np.flatnonzero(d[1:] > d[:-1])  # the first point after which the distance grows
        self.index += int(rising[0]) if len(rising) else len(d) - 1
        return self.path[self.index]

    def wheels(self, x: float, y: float, heading: float, axle: float, max_wheel: float) -> tuple[float, float]:
        cx, cy = self.carrot(x, y, heading)
        error = wrap(math.atan2(cy - y, cx - x) - heading)
        turn = self.k_fic * error
        v = self.speed * max(0.0, math.cos(error))
        left, right = v - turn * axle / 2, v + turn * axle / 2
        top = max(abs(left), abs(right))
        if top > max_wheel:
            left, right = left * max_wheel / top, right * max_wheel / top
        return left, right

    @property
    def at_end(self) -> bool:
        return self.index >= len(self.path) - 1


class PaperCarrotFollower(CarrotFollower):
    """Appendix B as printed: p_c the path point nearest p_look over the whole path (the first of equals),
    and forward at `speed` always, turning at k_fic * error at most as fast as the wheels allow."""

    def carrot(self, x: float, y: float, heading: float) -> np.ndarray:
        look = np.array([x + self.k_look * math.cos(heading), y + self.k_look * math.sin(heading)])
        self.index = int(np.argmin(((self.path - look) ** 2).sum(axis=1)))
        return self.path[self.index]

    def wheels(self, x: float, y: float, heading: float, axle: float, max_wheel: float) -> tuple[float, float]:
        cx, cy = self.carrot(x, y, heading)
        error = wrap(math.atan2(cy - y, cx - x) - heading)
        v = min(self.speed, max_wheel)
        top = 2 * (max_wheel - v) / axle  # the fastest turn that keeps both wheels within the limit at speed v
        turn = min(max(self.k_fic * error, -top), top)
        return v - turn * axle / 2, v + turn * axle / 2
