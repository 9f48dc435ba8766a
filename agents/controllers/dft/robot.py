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
from swarm.core.params import CODE, PAPER, declared


@dataclass(frozen=True)
class SensorLayout:
    """Where each proximity sensor ps0..ps7 writes into the proximity field, and how much it counts
    (IR_CELLS and IR_WEIGHT are taken from it)."""

    cells: tuple[int, ...] = declared(
        (55, 65, 90, 100, 1, 10, 35, 45),
        source=PAPER,
        where="Table 2: x_r = 0.1, "
        "0.3, 0.8, 1.0, -1.0, -0.8, -0.3, -0.1 pi, = (cell / 50 - 1) pi: 1-based cells "
        "of the 100 over [-pi, pi) (the code agrees: EPuckController.m, parameters.md "
        "section 10)",
    )
    weight: tuple[float, ...] = declared(
        (1.0, 1.0, 0.5, 0.5, 0.5, 0.5, 1.0, 1.0),
        source=CODE,
        where="EPuckController.m: the rear and side sensors ps2..ps5 count half "
        "(parameters.md section 10; not in the paper)",
    )


IR_CELLS = np.array(SensorLayout().cells, np.float64)
IR_WEIGHT = np.array(SensorLayout().weight)
CELL = np.arange(1, ANGLES + 1, dtype=np.float64)  # 1-based cells of the angular fields
ANGLE = -math.pi + (CELL - 1) * 2 * math.pi / ANGLES  # the wheel profile's axis


@dataclass(frozen=True)
class Interface:
    """The e-puck's face to the fields (equations 8-11, 16-17; parameters.md sections 8-10)."""

    heading_gain: float = declared(
        4.0,
        source=CODE,
        where="turnField.m: S_H peak 4, fed directly (no head-direction field; parameters.md section 8)",
    )
    heading_sigma: float = declared(
        30.0, source=CODE, where="turnField.m: S_H's Gaussian, 30 cells (parameters.md section 8)"
    )
    prox_strength: float = declared(
        5.0,
        source=PAPER,
        where="Table 2 and eq. 17: c_prox = 5, strength c_prox ln(1 + p / 50) (the code agrees: EPuckController.m)",
    )
    prox_sigma: float = declared(
        3.0, source=PAPER, where="Table 2: sigma_prox = 3 cells (the code agrees: EPuckController.m)"
    )
    v: float = declared(
        500.0, source=PAPER, where="Table 2 and eq. 10: v = 500 wheel units (the code agrees: createTurnField.m)"
    )
    alpha: float = declared(
        math.pi / 3, source=PAPER, where="Table 2: alpha = pi/3 (the code agrees: createTurnField.m)"
    )
    turn_limit: float = declared(
        400.0,
        source=CODE,
        where="EPuckController.m: |left - right| at most 400 (parameters.md section 9; not in the paper)",
    )

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
