"""Motivations and saliences of the BG animat (Girard et al. 2005, eq. 2 and
appendix A.2), one set per experiment.

The cortical feedback terms (0.4 P_E, 0.4 P_Ep, 0.2 P_i) are not here: they
are part of the loops' dynamics (gpr.py adds them at every step).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

SALIENCES = ("survival", "fear", "tmaze")  # eqs. 15-17 (exps. 1, 2); 15, 16, 18 (exp. 3.1); 19, 20 (exp. 3.2)


@dataclass(frozen=True)
class Drives:
    """What the saliences are made of this tick (RESOURCES order where indexed: DA, Ep, E)."""

    energy: float
    potential: float
    fear: float
    disorientation: float
    prox: np.ndarray  # (3, 36)
    usable: np.ndarray  # (3,) booleans A(.)
    plan: np.ndarray  # (3, 36) P(res) from the map (zeros without one)
    bka: np.ndarray  # (36,)
    expl: np.ndarray  # (36,)

    @property
    def m_e(self) -> float:
        return (1.0 - self.energy) * math.sqrt(max(0.0, 1.0 - (1.0 - self.potential) ** 2))

    @property
    def m_ep(self) -> float:
        return 1.0 - self.potential


def plan_vector(d: Drives, fear_term: bool) -> np.ndarray:
    """Eq. 1 (with -m(DA) P(DA) in experiment 3.1), clipped at 0 for the square root."""
    plan = 1.0 - (1.0 - d.m_e * d.plan[2]) * (1.0 - d.m_ep * d.plan[1])
    if fear_term:
        plan = plan - d.fear * d.plan[0]
    return np.maximum(plan, 0.0)


def saliences(d: Drives, kind: str, w_plan: float, w_taxon: float) -> tuple[np.ndarray, np.ndarray]:
    """(dorsal [ReloadE, ReloadEp], ventral 36) external saliences."""
    m_e, m_ep, m_bka = d.m_e, d.m_ep, d.disorientation
    mprox = d.prox.max(axis=1)
    a = d.usable.astype(np.float64)
    if kind == "tmaze":  # eqs. 19-20
        dorsal = np.array([0.9 * a[2] * m_e + 0.1 * mprox[2] * m_e, 0.9 * a[1] * m_ep + 0.1 * mprox[1] * m_ep])
    else:  # eqs. 15-16
        dorsal = np.array([1.2 * a[2] * m_e + 0.6 * mprox[2] * m_e, a[1] * m_ep + 0.2 * mprox[1] * m_ep])
    sq = np.sqrt(d.prox)
    plan = np.sqrt(plan_vector(d, kind == "fear"))
    if kind == "fear":  # eq. 18
        ventral = (0.45 * plan + 0.35 * sq[2] * m_e + 0.35 * sq[1] * m_ep + 0.19 * (1.0 - d.prox[0]) * d.fear
                   + 0.4 * d.bka * m_bka
                   + d.expl * (0.05 + 0.05 * (1 - mprox[1]) * m_ep + 0.05 * (1 - mprox[2]) * m_e))  # fmt: skip
        return dorsal, ventral
    # A.2.3: in the T-maze the plan term fades near resources, so the animat no longer stops short of them
    plan_term = 0.55 * plan * (1.0 - mprox[2]) * (1.0 - mprox[1]) if kind == "tmaze" else w_plan * plan
    ventral = (plan_term + 0.55 * sq[2] * m_e + w_taxon * sq[1] * m_ep + 0.4 * d.bka * m_bka
               + d.expl * (0.25 + 0.05 * (1 - mprox[1]) * m_ep + 0.05 * (1 - mprox[2]) * m_e))  # fmt: skip
    return dorsal, ventral
