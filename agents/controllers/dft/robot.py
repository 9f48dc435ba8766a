"""The SPA architecture's faces to the e-puck: the images its sensors write
into the input layers, and the wheel speeds its action fields give
(equations 8-11, 16-17).  Numbers are the original code's
(parameters.md sections 6-10), fields of Interface and SensorLayout (params.py).
"""

from __future__ import annotations

import math

import numpy as np

from agents.controllers.dft.architecture import ANGLES, EBS, HEADING
from agents.controllers.dft.params import Interface, SensorLayout

IR_CELLS = np.array(SensorLayout().cells, np.float64)
IR_WEIGHT = np.array(SensorLayout().weight)
CELL = np.arange(1, ANGLES + 1, dtype=np.float64)  # 1-based cells of the angular fields
ANGLE = -math.pi + (CELL - 1) * 2 * math.pi / ANGLES  # the wheel profile's axis


def heading_images(iface: Interface, yaw: float) -> dict[str, np.ndarray]:
    """Each action field's head-direction input: a Gaussian whose centre, cell 50, means 'facing the
    EB's direction'; cells above 50 lie to the robot's right (no wrap, as the original)."""
    out = {}
    for d in EBS:
        p = (50.0 + ANGLES * ((yaw - HEADING[d]) % (2 * math.pi)) / (2 * math.pi)) % ANGLES
        out[d] = iface.heading_gain * np.exp(-((CELL - p) ** 2) / (2 * iface.heading_sigma**2))
    return out


def ir_image(iface: Interface, readings: np.ndarray) -> np.ndarray:
    """Equation 17 summed over the sensors: a bump of c_prox ln(1 + p/50) at each sensor's cell."""
    strength = iface.prox_strength * np.log1p(np.maximum(np.asarray(readings, np.float64), 0.0) / 50.0) * IR_WEIGHT
    bumps = np.exp(-((CELL[None, :] - IR_CELLS[:, None]) ** 2) / (2 * iface.prox_sigma**2))
    return strength @ bumps


def wheel_profiles(iface: Interface) -> tuple[np.ndarray, np.ndarray]:
    left = iface.v * np.sin(ANGLE + iface.alpha)
    return left, left[::-1].copy()  # the right wheel's profile is the left's mirror image


def wheel_speeds(iface: Interface, outputs: dict[str, np.ndarray]) -> tuple[float, float]:
    """Equations 8-11 summed over the EBs' action fields, then the turn limit; in wheel units."""
    lw, rw = wheel_profiles(iface)
    left = right = 0.0
    for f in outputs.values():
        fl, fr = f * lw, f * rw
        left += float(fl.max() + fl.min())
        right += float(fr.max() + fr.min())
    spread = abs(left - right)
    if spread > iface.turn_limit:
        left, right = left * iface.turn_limit / spread, right * iface.turn_limit / spread
    return left, right


def gaussian_2d(shape: tuple[int, int], cj: float, ci: float, sigma: float, peak: float) -> np.ndarray:
    """A plain (unnormalised, unwrapped) Gaussian at continuous cell coordinates (cj, ci)."""
    gj = np.exp(-((np.arange(shape[0]) - cj) ** 2) / (2 * sigma**2))
    gi = np.exp(-((np.arange(shape[1]) - ci) ** 2) / (2 * sigma**2))
    return peak * np.outer(gj, gi)
