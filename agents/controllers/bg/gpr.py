"""The GPR basal ganglia (Gurney, Prescott & Redgrave 2001) as Girard et al.
(2005) use it: two cortico-basal ganglia-thalamo-cortical loops, a dorsal one
over consummatory acts and a ventral one over 36 directions of movement,
joined by the trans-subthalamic projection (dorsal STN onto ventral EP/SNr).

Every channel of every nucleus is one leaky integrator, tau da/dt = I - a
(eq. 3), with the piecewise-linear output of eq. 4 and Table 5.  Inputs are
eqs. 5-14 with two printing slips of the paper read as the text means them:
the lateral sums of eqs. 5-7 are over the other channels' outputs (y^j, not
y^i), and the ventral lateral weight of eq. 7 is the circular channel distance
over N/2 (|i - j| mod N/2 would let opposite directions not compete at all,
against the text: "close directions compete less than opposite ones").

The salience a loop receives includes the thalamo-cortical feedback P (the
`0.4 P_E` and `0.2 P_i` terms of eqs. 15-17): it is part of the dynamics, so
the engine adds `feedback * y_P` to the external salience at every step.

Integration: explicit Euler at dt = 1 ms.  With the diffuse STN projection
explicit Euler is stable only for dt / tau < 2 / (1 + 0.9 N); at N = 36 and
tau = 25 ms that is dt < 1.5 ms (docs/bg.md).  An exponential step at larger
dt is not the cure: the instability is in the coupling, not in each neuron.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from agents.controllers.bg.params import GprParams
from swarm.core.kernels import exported, njit

# Nuclei, in the order of the state's rows.
D1, D2, STN, GP, EP, VL, TRN, CTX = range(8)
NUCLEI = ("D1", "D2", "STN", "GP", "EP/SNr", "VL", "TRN", "Ctx")


GPR = GprParams()
EPSILON = np.array(GPR.epsilon)
SLOPE = np.array(GPR.slope)
TAU = GPR.tau  # s (the paper; Gurney's own code uses a gain of 25, tau = 40 ms)
DOPAMINE = GPR.dopamine  # lambda
DT = GPR.dt  # s, the Euler step (stable below 1.5 ms at 36 channels)


def lateral_uniform(n: int) -> np.ndarray:
    """The dorsal striatum's lateral inhibition: every other channel, weight 1 (eqs. 5-6)."""
    return np.ones((n, n)) - np.eye(n)


def lateral_circular(n: int) -> np.ndarray:
    """The ventral striatum's: the circular distance between channels over N/2 (eq. 7, read as the text says)."""
    i = np.arange(n)
    d = np.abs(i[:, None] - i[None, :])
    return np.minimum(d, n - d) / (n / 2)


@njit(cache=True, inline="always")
def _out(a: float, eps: float, m: float) -> float:
    return min(max(m * (a - eps), 0.0), 1.0)  # without branches, so the loops over channels vectorise


@exported("bg_outputs", "void(float64[:, :], float64[:, :], float64[:], float64[:])")
@njit(cache=True, inline="always")  # inlined in run_loops, with _euler: a fifth off the period's 250 steps
def _outputs(a: np.ndarray, y: np.ndarray, eps: np.ndarray, slope: np.ndarray) -> None:
    for k in range(a.shape[0]):
        for i in range(a.shape[1]):
            y[k, i] = _out(a[k, i], eps[k], slope[k])


@njit(cache=True, inline="always")
def _euler(a: np.ndarray, y: np.ndarray, salience: np.ndarray, feedback: float, ctx_rest: np.ndarray,
           lateral: np.ndarray, stn_other: float, dopamine: float, h: float, sums: np.ndarray) -> None:  # fmt: skip
    """One Euler step of one loop in place: a += h (I - a), the inputs I of eqs. 5-14 from the outputs `y`.
    `stn_other` is the sum of the other loop's STN outputs this loop's EP/SNr receives (eq. 10, times 0.4);
    `sums` (2, N) is scratch for the lateral sums; `lateral` is symmetric.  One simple loop per nucleus
    (the compiler vectorises those; one loop computing all eight did not), each input in the same order of
    operations as eqs. 5-14 are written, so the result is the same to the bit."""
    n = y.shape[1]
    stn_sum, trn_sum = 0.0, 0.0
    for j in range(n):
        stn_sum += y[STN, j]
        trn_sum += y[TRN, j]
    for i in range(n):
        sums[0, i] = 0.0
        sums[1, i] = 0.0
    for j in range(n):  # over the striatal channels with output (few), along a row of `lateral`
        y1, y2 = y[D1, j], y[D2, j]
        if y1 > 0.0 or y2 > 0.0:
            for i in range(n):  # both sums in one loop: half the loops' set-up, for 36 channels a share
                sums[0, i] += lateral[j, i] * y1
                sums[1, i] += lateral[j, i] * y2
    up, down = 1.0 + dopamine, 1.0 - dopamine
    for i in range(n):
        c = y[CTX, i] - ctx_rest[i]
        s = salience[i] + feedback * (c if c > 0.0 else 0.0)
        a[D1, i] += h * ((up * s - sums[0, i]) - a[D1, i])
        a[D2, i] += h * ((down * s - sums[1, i]) - a[D2, i])
        a[STN, i] += h * ((s - y[GP, i]) - a[STN, i])
    diffuse = 0.8 * stn_sum
    for i in range(n):
        a[GP, i] += h * ((-y[D2, i] + diffuse) - a[GP, i])
    for i in range(n):
        a[EP, i] += h * ((-y[D1, i] - 0.4 * y[GP, i] + diffuse + stn_other) - a[EP, i])
    for i in range(n):
        a[VL, i] += h * ((y[CTX, i] - y[EP, i] - 0.13 * (trn_sum - y[TRN, i])) - a[VL, i])
    for i in range(n):
        a[TRN, i] += h * ((y[VL, i] + y[CTX, i]) - a[TRN, i])
    for i in range(n):
        a[CTX, i] += h * (y[VL, i] - a[CTX, i])


@exported("bg_run_loops", "void(float64[:, :], float64[:, :], float64[:], float64[:], float64, float64, "
          "float64[:], float64[:], float64[:, :], float64[:, :], float64, int64, float64, float64, float64[:], "
          "float64[:])")  # fmt: skip
@njit(cache=True)
def run_loops(a_d: np.ndarray, a_v: np.ndarray, s_d: np.ndarray, s_v: np.ndarray, fb_d: float, fb_v: float,
              rest_d: np.ndarray, rest_v: np.ndarray, lat_d: np.ndarray, lat_v: np.ndarray, cross: float, steps: int,
              h: float, dopamine: float, eps: np.ndarray, slope: np.ndarray) -> None:  # fmt: skip
    """`steps` Euler steps of h = dt / tau of both loops in place; `cross` weighs
    the dorsal STN's sum onto the ventral EP/SNr (0.4 in eq. 10; 0 for a lone loop)."""
    y_d, y_v = np.empty_like(a_d), np.empty_like(a_v)
    sums_d, sums_v = np.empty((2, a_d.shape[1])), np.empty((2, a_v.shape[1]))
    for _ in range(steps):
        _outputs(a_d, y_d, eps, slope)
        _outputs(a_v, y_v, eps, slope)
        dorsal_stn = 0.0
        for j in range(a_d.shape[1]):
            dorsal_stn += y_d[STN, j]
        _euler(a_d, y_d, s_d, fb_d, rest_d, lat_d, 0.0, dopamine, h, sums_d)
        _euler(a_v, y_v, s_v, fb_v, rest_v, lat_v, cross * dorsal_stn, dopamine, h, sums_v)


@exported("bg_disinhibition", "void(float64[:, :], float64, float64, float64[:], float64[:])")
@njit(cache=True)
def _disinhibition(a: np.ndarray, eps: float, slope: float, rest: np.ndarray, out: np.ndarray) -> None:
    """Per channel 1 - y_EP / max(rest, 1e-9): how far below its resting level the EP/SNr output is."""
    for i in range(out.shape[0]):
        out[i] = 1.0 - _out(a[EP, i], eps, slope) / max(rest[i], 1e-9)


def outputs(a: np.ndarray) -> np.ndarray:
    y = np.empty_like(a)
    _outputs(a, y, EPSILON, SLOPE)
    return y


@dataclass(frozen=True)
class LoopSpec:
    channels: int
    feedback: float  # weight of the cortical feedback P in the salience (eqs. 15-17: 0.4 dorsal, 0.2 ventral)
    circular: bool  # lateral inhibition by channel distance (ventral) or uniform (dorsal)

    def lateral(self) -> np.ndarray:
        return lateral_circular(self.channels) if self.circular else lateral_uniform(self.channels)


DORSAL = LoopSpec(channels=2, feedback=GPR.feedback_dorsal, circular=False)
VENTRAL = LoopSpec(channels=GPR.ventral_channels, feedback=GPR.feedback_ventral, circular=True)


class BasalGanglia:
    """Two GPR loops stepped together; `cross` is the trans-subthalamic weight
    (0.4, eq. 10).  The cortical feedback counts from the cortex's resting level
    (docs/bg.md); `literal_feedback` feeds back the cortex's whole output, as eqs.
    15-20 print it (an ablation).  A lone loop for tests: a ventral spec of 0 channels."""

    def __init__(self, dorsal: LoopSpec = DORSAL, ventral: LoopSpec = VENTRAL, cross: float = GPR.cross,
                 dt: float = DT, tau: float = TAU, dopamine: float = DOPAMINE,
                 literal_feedback: bool = False):  # fmt: skip
        self.dorsal, self.ventral, self.cross = dorsal, ventral, cross
        self.h, self.dopamine, self.dt = dt / tau, dopamine, dt
        self.lat_d, self.lat_v = dorsal.lateral(), ventral.lateral()
        if not (np.array_equal(self.lat_d, self.lat_d.T) and np.array_equal(self.lat_v, self.lat_v.T)):
            raise ValueError("the striatal lateral weights must be symmetric (_euler sums along rows)")
        self.a_d = np.zeros((8, dorsal.channels))
        self.a_v = np.zeros((8, ventral.channels))
        # The resting state (zero salience), settled: the feedback counts from its cortex level and
        # disinhibition from its EP/SNr level.  At rest the feedback is then 0, so the probe needs none.
        self.ctx_rest_d, self.ctx_rest_v = np.full(dorsal.channels, np.inf), np.full(ventral.channels, np.inf)
        self.run(np.zeros(dorsal.channels), np.zeros(ventral.channels), 2.0)
        y_d, y_v = outputs(self.a_d), outputs(self.a_v)
        self.ctx_rest_d, self.ctx_rest_v = y_d[CTX].copy(), y_v[CTX].copy()
        if literal_feedback:  # the cortex's whole output fed back, at rest too; disinhibition from the same rest
            self.ctx_rest_d, self.ctx_rest_v = np.zeros(dorsal.channels), np.zeros(ventral.channels)
        self.rest_d, self.rest_v = y_d[EP].copy(), y_v[EP].copy()
        self.a_d[...], self.a_v[...] = 0.0, 0.0

    def run(self, s_dorsal: np.ndarray, s_ventral: np.ndarray, seconds: float) -> None:
        """Integrate both loops for `seconds` with these external saliences held."""
        steps = round(seconds / self.dt)
        run_loops(self.a_d, self.a_v, np.ascontiguousarray(s_dorsal, np.float64),
                  np.ascontiguousarray(s_ventral, np.float64), self.dorsal.feedback, self.ventral.feedback,
                  self.ctx_rest_d, self.ctx_rest_v, self.lat_d, self.lat_v, self.cross, steps, self.h, self.dopamine,
                  EPSILON, SLOPE)  # fmt: skip

    def y_dorsal(self) -> np.ndarray:
        return outputs(self.a_d)

    def y_ventral(self) -> np.ndarray:
        return outputs(self.a_v)

    def disinhibition(self) -> tuple[np.ndarray, np.ndarray]:
        """Per channel, how far below its resting level the EP/SNr output is, as a
        share of that level (1: fully released, 0 or less: not)."""
        d, v = np.empty(self.dorsal.channels), np.empty(self.ventral.channels)
        _disinhibition(self.a_d, EPSILON[EP], SLOPE[EP], self.rest_d, d)
        _disinhibition(self.a_v, EPSILON[EP], SLOPE[EP], self.rest_v, v)
        return d, v

    def state(self) -> dict[str, np.ndarray]:
        return {"a_d": self.a_d.copy(), "a_v": self.a_v.copy()}

    def restore(self, state: dict[str, np.ndarray]) -> None:
        self.a_d[...] = state["a_d"]
        self.a_v[...] = state["a_v"]


def select_dorsal(disinhibition: np.ndarray, threshold: float | Sequence[float], incumbent: int = -1) -> int:
    """Winner-takes-all: the most disinhibited channel if it is released beyond `threshold` (one for every
    channel, or one per channel) -- or, for the channel selected last (`incumbent`), released at all (below
    its resting output): an act goes on until its channel is inhibited again, as the thalamo-cortical
    loop's persistence means it to.  Else -1.  (Plain indexing, no numpy call but argmax: this runs
    every control period.)"""
    k = int(disinhibition.argmax())
    own = float(threshold) if isinstance(threshold, (int, float)) else float(threshold[k])
    return k if disinhibition[k] > (0.0 if k == incumbent else own) else -1


@exported("bg_released", "float64(float64[::1], float64, float64[::1])")
@njit(cache=True)
def _released(disinhibition: np.ndarray, threshold: float, w: np.ndarray) -> float:
    """w = np.maximum(disinhibition - threshold, 0.0); returns w.sum() in numpy's order (its pairwise sum:
    eight running sums, then the rest in turn; numpy/_core/src/umath/loops_utils.h.src), to the bit."""
    n = w.shape[0]
    for i in range(n):
        x = disinhibition[i] - threshold
        w[i] = x if x > 0.0 or x != x else 0.0  # np.maximum keeps nan
    if n < 8:
        total = -0.0  # numpy's reduction starts from the identity -0.0, as its loop does
        for i in range(n):
            total += w[i]
        return total
    if n > 128:
        raise ValueError("more than 128 channels: numpy splits the sum further")
    r0, r1, r2, r3, r4, r5, r6, r7 = w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7]
    i = 8
    while i < n - n % 8:
        r0 += w[i]
        r1 += w[i + 1]
        r2 += w[i + 2]
        r3 += w[i + 3]
        r4 += w[i + 4]
        r5 += w[i + 5]
        r6 += w[i + 6]
        r7 += w[i + 7]
        i += 8
    total = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        total += w[i]
        i += 1
    return total


@functools.cache
def _circle(n: int) -> tuple[np.ndarray, np.ndarray]:
    """cos and sin of the N channels' directions (channel i points at i * 360/N degrees)."""
    angle = np.arange(n) * (2 * np.pi / n)
    return np.cos(angle), np.sin(angle)


def select_ventral(disinhibition: np.ndarray, threshold: float, min_share: float = 0.1) -> tuple[float, float]:
    """(direction, strength): the vector sum of the channels released beyond
    `threshold`, each weighted by how far beyond it (channel i points at
    i * 360/N degrees); strength 0 (direction nan) when none is, or when the
    released channels point every way (their sum is under `min_share` of their weight)."""
    w = np.empty(len(disinhibition))  # each channel's weight: how far beyond the threshold
    total = _released(np.ascontiguousarray(disinhibition, np.float64), float(threshold), w)
    if total == 0.0:  # none beyond it
        return float("nan"), 0.0
    cos, sin = _circle(len(disinhibition))
    x, y = float(w.dot(cos)), float(w.dot(sin))  # w @ cos's BLAS sums, with less of numpy's dispatch
    length = float(np.hypot(x, y))
    if length < min_share * total:
        return float("nan"), 0.0
    return math.atan2(y, x) % (2 * math.pi), length  # libm's atan2, as np.arctan2
