"""The SPA architecture's faces to the e-puck: the images its sensors write
into the input layers, and the wheel speeds its action fields give
(equations 8-11, 16-17).  Numbers are the original code's
(parameters.md sections 6-10).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from agents.controllers.dft.architecture import ANGLES, EBS, HEADING

# Field cell (1-based, 1..100 over [-pi, pi)) of each proximity sensor ps0..ps7, and its weight
# (the rear and side sensors ps2..ps5 count half in the original code).
IR_CELLS = np.array([55, 65, 90, 100, 1, 10, 35, 45], np.float64)
IR_WEIGHT = np.array([1.0, 1.0, 0.5, 0.5, 0.5, 0.5, 1.0, 1.0])
CELL = np.arange(1, ANGLES + 1, dtype=np.float64)  # 1-based cells of the angular fields
ANGLE = -math.pi + (CELL - 1) * 2 * math.pi / ANGLES  # the wheel profile's axis


@dataclass(frozen=True)
class Interface:
    heading_gain: float = 4.0  # S_H peak
    heading_sigma: float = 30.0  # cells
    prox_strength: float = 5.0  # c_prox: strength = c_prox * ln(1 + p / 50)
    prox_sigma: float = 3.0  # cells
    v: float = 500.0  # wheel units (equation 10)
    alpha: float = math.pi / 3
    turn_limit: float = 400.0  # |left - right| at most this (original code)

    def heading_images(self, yaw: float) -> dict[str, np.ndarray]:
        """Each action field's head-direction input: a Gaussian whose centre, cell 50, means 'facing the
        EB's direction'; cells above 50 lie to the robot's right (no wrap, as the original)."""
        out = {}
        for d in EBS:
            p = (50.0 + ANGLES * ((yaw - HEADING[d]) % (2 * math.pi)) / (2 * math.pi)) % ANGLES
            out[d] = self.heading_gain * np.exp(-((CELL - p) ** 2) / (2 * self.heading_sigma**2))
        return out

    def ir_image(self, readings: np.ndarray) -> np.ndarray:
        """Equation 17 summed over the sensors: a bump of c_prox ln(1 + p/50) at each sensor's cell."""
        strength = self.prox_strength * np.log1p(np.maximum(np.asarray(readings, np.float64), 0.0) / 50.0) * IR_WEIGHT
        bumps = np.exp(-((CELL[None, :] - IR_CELLS[:, None]) ** 2) / (2 * self.prox_sigma**2))
        return strength @ bumps

    def wheel_profiles(self) -> tuple[np.ndarray, np.ndarray]:
        left = self.v * np.sin(ANGLE + self.alpha)
        return left, left[::-1].copy()  # the right wheel's profile is the left's mirror image

    def wheels(self, outputs: dict[str, np.ndarray]) -> tuple[float, float]:
        """Equations 8-11 summed over the EBs' action fields, then the turn limit; in wheel units."""
        lw, rw = self.wheel_profiles()
        left = right = 0.0
        for f in outputs.values():
            fl, fr = f * lw, f * rw
            left += float(fl.max() + fl.min())
            right += float(fr.max() + fr.min())
        spread = abs(left - right)
        if spread > self.turn_limit:
            left, right = left * self.turn_limit / spread, right * self.turn_limit / spread
        return left, right


def gaussian_2d(shape: tuple[int, int], cj: float, ci: float, sigma: float, peak: float) -> np.ndarray:
    """A plain (unnormalised, unwrapped) Gaussian at continuous cell coordinates (cj, ci)."""
    gj = np.exp(-((np.arange(shape[0]) - cj) ** 2) / (2 * sigma**2))
    gi = np.exp(-((np.arange(shape[1]) - ci) ** 2) / (2 * sigma**2))
    return peak * np.outer(gj, gi)
