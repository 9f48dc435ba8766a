"""The animat's face on its sensors (Girard et al. 2005, section 3.2).

The camera gives the colour of the nearest thing in each 10-degree sector;
the BG model reads three kinds of resource from it by their grey level
(ingesting 127, digesting 255, dangerous 31: the simulator's visual sensors
see colours directly).  Channels of the ventral loop are allocentric
directions, so every egocentric reading is turned by the compass first.
"""

from __future__ import annotations

import math

import numpy as np

from agents.controllers.bg.params import SenseParams
from swarm.core.kernels import exported, njit

RESOURCES = ("DA", "Ep", "E")  # dangerous, potential energy (ingesting), energy (digesting)


SENSES = SenseParams()
RESOURCE_GREY = np.array(SENSES.grey)
WINDOW = SENSES.window  # pixels (sectors) of the window centred on each direction (the paper)
_HALF = WINDOW // 2


def to_allocentric(readings: np.ndarray, heading: float) -> np.ndarray:
    """Readings of equally spaced egocentric bearings (k * 360/n degrees from the
    heading) resampled at the allocentric directions k * 360/n, linearly
    between neighbours."""
    out = np.empty(len(readings))
    _allocentric(np.ascontiguousarray(readings, np.float64), float(heading), out)
    return out


@exported("bg_allocentric", "void(float64[::1], float64, float64[::1])")
@njit(cache=True)
def _allocentric(readings: np.ndarray, heading: float, out: np.ndarray) -> None:
    """`to_allocentric` compiled, in numpy's order of operations (its numbers to the bit)."""
    n = readings.shape[0]
    turn = heading * n / (2 * math.pi)
    for k in range(n):
        pos = (k - turn) % n  # where direction k falls among the bearings
        lo = math.floor(pos)
        f = pos - lo
        out[k] = readings[lo] * (1 - f) + readings[(lo + 1) % n] * f


def resource_pixels(grey: np.ndarray, heading: float) -> np.ndarray:
    """(3, n) booleans: which allocentric sectors show each resource (RESOURCES order).
    Sector k of the camera points at heading + k * 360/n; it goes to the nearest direction."""
    n = len(grey)
    pixels = np.empty((len(RESOURCE_GREY), n), np.bool_)
    _pixels(np.ascontiguousarray(grey, np.float64), _shift(n, heading), _GREY_LEVELS, pixels)
    return pixels


def _shift(n: int, heading: float) -> int:
    """The camera's sectors to turn by: heading in whole sectors, to the nearest."""
    return round(heading * n / (2 * math.pi)) % n


_GREY_LEVELS = RESOURCE_GREY.astype(np.float64)


@njit(cache=True)
def _pixels(grey: np.ndarray, shift: int, levels: np.ndarray, pixels: np.ndarray) -> None:
    """`resource_pixels` compiled: direction k shows sector k - shift."""
    n = grey.shape[0]
    for r in range(levels.shape[0]):
        for k in range(n):
            pixels[r, k] = grey[(k - shift) % n] == levels[r]


def proximity(pixels: np.ndarray) -> np.ndarray:
    """Prox vectors (3, n): per direction, the contiguous pixels of the resource
    in the 7-pixel window centred on it -- the run through the centre pixel,
    cut to the window -- over 7.  0 where the centre pixel does not show the
    resource (so a direction points at what it sees), 1 when the resource
    fills the window (it then spans more than 60 degrees: the paper's A(.))."""
    out = np.empty(pixels.shape)
    _runs(np.ascontiguousarray(pixels, np.bool_), out)
    return out


@exported("bg_runs", "void(boolean[:, ::1], float64[:, :])")
@njit(cache=True)
def _runs(pixels: np.ndarray, out: np.ndarray) -> None:
    """`proximity` compiled: 36 directions x 3 resources of a few pixels each are 100 small numpy calls."""
    kinds, n = pixels.shape
    for r in range(kinds):
        for d in range(n):
            if not pixels[r, d]:
                out[r, d] = 0.0
                continue
            right = 1  # the centre and the run after it, within the window
            while right <= _HALF and pixels[r, (d + right) % n]:
                right += 1
            left = 1  # ... and before it
            while left <= _HALF and pixels[r, (d - left) % n]:
                left += 1
            out[r, d] = (left + right - 1) / WINDOW


def sense(grey: np.ndarray, heading: float) -> tuple[np.ndarray, np.ndarray]:
    """(proximity(resource_pixels(grey, heading)), which resources show in any direction): what the
    animat reads off its camera every control period, in one compiled pass instead of some ten numpy calls."""
    n = len(grey)
    pixels, prox, seen = np.empty((len(RESOURCE_GREY), n), np.bool_), np.empty((len(RESOURCE_GREY), n)), \
        np.empty(len(RESOURCE_GREY), np.bool_)  # fmt: skip
    _sense(np.ascontiguousarray(grey, np.float64), _shift(n, heading), _GREY_LEVELS, pixels, prox, seen)
    return prox, seen


@exported("bg_sense", "void(float64[::1], int64, float64[::1], boolean[:, ::1], float64[:, ::1], boolean[::1])")
@njit(cache=True)
def _sense(grey: np.ndarray, shift: int, levels: np.ndarray, pixels: np.ndarray, prox: np.ndarray,
           seen: np.ndarray) -> None:  # fmt: skip
    """`sense` compiled: the resource pixels, then their runs (proximity), then which resources show."""
    _pixels(grey, shift, levels, pixels)
    _runs(pixels, prox)
    n = grey.shape[0]
    for r in range(levels.shape[0]):
        seen[r] = False
        for k in range(n):
            if prox[r, k] != 0.0:
                seen[r] = True


SIDE = SENSES.side


class Reflex:
    """The sonar obstacle-avoidance reflex that overrides the BG's choice when
    something is nearer than `too_close` straight ahead, or nearer than a
    third of it to the sonars at +-45 degrees.  It turns away, to the side with more room (chosen when it
    starts and kept, so it does not flip between two walls), backing off when
    nearly touching; once the front is clear it drives straight on for `hold`
    seconds, past the obstacle, before giving the BG back the body."""

    def __init__(self, too_close: float, hold: float):
        self.too_close, self.hold = too_close, hold
        self.side = 0  # +1 turning left, -1 right, 0 off
        self.clear_for = math.inf  # seconds since the front became clear

    def __call__(self, sonar: np.ndarray, dt: float) -> tuple[float, float] | None:
        """(forward factor of the top speed, turn sign) while the reflex has the body, else None."""
        n = len(sonar)
        # straight ahead at `too_close`; the +-45 degree sonars at a third of it: in the bg corridors
        # (0.8 m for a 0.3 m body) anything more sets the reflex off at every sway
        if sonar[0] < self.too_close or min(sonar[1], sonar[n - 1]) < self.too_close * SIDE:
            if self.side == 0:
                self.side = 1 if sonar[1 : n // 2].mean() >= sonar[n // 2 + 1 :].mean() else -1
            self.clear_for = 0.0
            return (-0.25 if sonar[0] < 0.6 * self.too_close else 0.0), float(self.side)
        self.side = 0
        self.clear_for += dt
        return (1.0, 0.0) if self.clear_for < self.hold else None

    def state(self) -> list[float]:
        return [float(self.side), self.clear_for]

    def restore(self, state: list[float]) -> None:
        self.side, self.clear_for = int(state[0]), float(state[1])
