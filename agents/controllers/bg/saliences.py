"""Motivations and saliences of the BG animat (Girard et al. 2005, eq. 2 and
appendix A.2), one set per experiment.

The cortical feedback terms (0.4 P_E, 0.4 P_Ep, 0.2 P_i) are not here: they
are part of the loops' dynamics (gpr.py adds them at every step).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from agents.controllers.bg.params import SALIENCES
from swarm.core.kernels import exported, njit


@dataclass(slots=True)  # not frozen: a frozen dataclass sets each field through object.__setattr__, every tick
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
    out = np.empty(d.plan.shape[1])
    _plan(d.m_e, d.m_ep, d.fear, np.ascontiguousarray(d.plan, np.float64), fear_term, out)
    return out


def saliences(d: Drives, kind: str, w_plan: float, w_taxon: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(dorsal [ReloadE, ReloadEp], ventral 36) external saliences, and the plan vector of eq. 1 in them."""
    n = d.plan.shape[1]
    dorsal, ventral, plan = np.empty(2), np.empty(n), np.empty(n)
    _saliences(SALIENCES.index(kind), np.ascontiguousarray(d.prox, np.float64), d.usable.astype(np.float64),
               np.ascontiguousarray(d.plan, np.float64), np.ascontiguousarray(d.bka, np.float64),
               np.ascontiguousarray(d.expl, np.float64), d.m_e, d.m_ep, d.disorientation, d.fear, w_plan, w_taxon,
               dorsal, ventral, plan)  # fmt: skip
    return dorsal, ventral, plan


# The two kernels below are eqs. 1 and 15-20 over the 36 directions, compiled (as numpy they were some 30
# small calls a tick).  Each sum and product is written in the order of the equations, so they give the
# numbers numpy gave, to the bit.


@exported("bg_plan", "void(float64, float64, float64, float64[:, ::1], boolean, float64[::1])")
@njit(cache=True)
def _plan(m_e: float, m_ep: float, fear: float, plan: np.ndarray, fear_term: bool, out: np.ndarray) -> None:
    for i in range(out.shape[0]):
        v = 1.0 - (1.0 - m_e * plan[2, i]) * (1.0 - m_ep * plan[1, i])
        if fear_term:
            v = v - fear * plan[0, i]
        out[i] = v if (v >= 0.0 or v != v) else 0.0  # np.maximum(v, 0.0), NaN kept


@exported("bg_saliences", "void(int64, float64[:, ::1], float64[::1], float64[:, ::1], float64[::1], "
          "float64[::1], float64, float64, float64, float64, float64, float64, float64[::1], float64[::1], "
          "float64[::1])")  # fmt: skip
@njit(cache=True)
def _saliences(kind: int, prox: np.ndarray, a: np.ndarray, plan: np.ndarray, bka: np.ndarray, expl: np.ndarray,
               m_e: float, m_ep: float, m_bka: float, fear: float, w_plan: float, w_taxon: float,
               dorsal: np.ndarray, ventral: np.ndarray, planned: np.ndarray) -> None:  # fmt: skip
    """kind: 0 survival (eqs. 15-17), 1 fear (15, 16, 18), 2 tmaze (19, 20; A.2.3's fading plan term)."""
    n = ventral.shape[0]
    mprox = np.empty(3)
    for r in range(3):
        mprox[r] = prox[r].max()
    if kind == 2:  # eqs. 19-20
        dorsal[0] = 0.9 * a[2] * m_e + 0.1 * mprox[2] * m_e
        dorsal[1] = 0.9 * a[1] * m_ep + 0.1 * mprox[1] * m_ep
    else:  # eqs. 15-16
        dorsal[0] = 1.2 * a[2] * m_e + 0.6 * mprox[2] * m_e
        dorsal[1] = a[1] * m_ep + 0.2 * mprox[1] * m_ep
    _plan(m_e, m_ep, fear, plan, kind == 1, planned)
    if kind == 1:  # eq. 18
        e = 0.05 + 0.05 * (1.0 - mprox[1]) * m_ep + 0.05 * (1.0 - mprox[2]) * m_e
        for i in range(n):
            ventral[i] = (0.45 * math.sqrt(planned[i]) + 0.35 * math.sqrt(prox[2, i]) * m_e
                          + 0.35 * math.sqrt(prox[1, i]) * m_ep + 0.19 * (1.0 - prox[0, i]) * fear
                          + 0.4 * bka[i] * m_bka + expl[i] * e)  # fmt: skip
        return
    e = 0.25 + 0.05 * (1.0 - mprox[1]) * m_ep + 0.05 * (1.0 - mprox[2]) * m_e
    for i in range(n):
        p = math.sqrt(planned[i])
        # A.2.3: in the T-maze the plan term fades near resources, so the animat no longer stops short of them
        term = 0.55 * p * (1.0 - mprox[2]) * (1.0 - mprox[1]) if kind == 2 else w_plan * p
        ventral[i] = (term + 0.55 * math.sqrt(prox[2, i]) * m_e + w_taxon * math.sqrt(prox[1, i]) * m_ep
                      + 0.4 * bka[i] * m_bka + expl[i] * e)  # fmt: skip
