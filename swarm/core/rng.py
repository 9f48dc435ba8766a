"""Counter-based random numbers keyed by (seed, agent, tick, draw).

A draw depends only on who asks, when, and which draw it is, never on the order
in which agents are stepped.  That is what lets one agent process, alone on its
machine, make exactly the choices it would make inside the in-process engine.
"""

import numpy as np

from swarm.core.kernels import exported, njit

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_TICK_MULT = np.uint64(0xD1B54A32D192ED03)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_S30 = np.uint64(30)
_S27 = np.uint64(27)
_S31 = np.uint64(31)
_S32 = np.uint64(32)


@njit(cache=True, inline="always")
def mix64(z):
    """SplitMix64 finaliser: a bijective avalanche on 64-bit words."""
    z = (z ^ (z >> _S30)) * _M1
    z = (z ^ (z >> _S27)) * _M2
    return z ^ (z >> _S31)


@njit(cache=True, inline="always")
def draw_u64(seed, agent, tick, draw):
    """A 64-bit random word for draw number `draw` of `agent` at `tick`."""
    h = mix64(np.uint64(seed) + _GOLDEN * np.uint64(agent + 1))
    return mix64(h ^ (np.uint64(tick) * _TICK_MULT + np.uint64(draw)))


@njit(cache=True, inline="always")
def draw_below(seed, agent, tick, draw, n):
    """A uniform integer in [0, n) by multiply-shift of 32 random bits (bias < 2**-28
    for the n <= 16 that controllers ask for)."""
    return np.int64(((draw_u64(seed, agent, tick, draw) >> _S32) * np.uint64(n)) >> _S32)


_TO_UNIT = 1.0 / 9007199254740992.0  # 2**-53
_S11 = np.uint64(11)


@njit(cache=True, inline="always")
def draw_unit(seed, agent, tick, draw):
    """A uniform float in [0, 1) from the top 53 bits of one draw."""
    return np.float64(draw_u64(seed, agent, tick, draw) >> _S11) * _TO_UNIT


@njit(cache=True, inline="always")
def draw_normal(seed, agent, tick, draw):
    """A standard normal (Box-Muller over draws 2*draw and 2*draw + 1): each
    normal owns two counters, so no draw is shared between normals."""
    u1 = 1.0 - draw_unit(seed, agent, tick, 2 * draw)  # (0, 1]: log is finite
    u2 = draw_unit(seed, agent, tick, 2 * draw + 1)
    return np.sqrt(-2.0 * np.log(u1)) * np.cos(2.0 * np.pi * u2)


@njit(cache=True, inline="always")
def normal_row(seed, agent, tick, stream, row):
    """Row of `agent` for fill_normal: its counters (stream << 24) + j at tick."""
    for j in range(0, row.shape[0], 2):
        base = 2 * ((stream << 24) + j)
        u1 = 1.0 - draw_unit(seed, agent, tick, base)
        u2 = draw_unit(seed, agent, tick, base + 1)
        radius = np.sqrt(-2.0 * np.log(u1))
        row[j] = radius * np.cos(2.0 * np.pi * u2)
        if j + 1 < row.shape[0]:
            row[j + 1] = radius * np.sin(2.0 * np.pi * u2)


@njit(cache=True)
def fill_normal(seed, agents, tick, stream, out):
    """The noise of one sensor for every robot in one call: row i from agents[i]'s
    counters (stream << 24) + j at tick (streams never overlap).  Box-Muller
    gives two normals per pair of uniforms; both are used."""
    for i in range(out.shape[0]):
        normal_row(seed, agents[i], tick, stream, out[i])


@exported("rng_fill_uniform", "void(int64, int64[:], int64, int64, float64[:, :])")
@njit(cache=True)
def fill_uniform(seed, agents, tick, stream, out):
    """Like fill_normal, uniform in [-1, 1) (the papers' +-bounds)."""
    for i in range(out.shape[0]):
        for j in range(out.shape[1]):
            out[i, j] = 2.0 * draw_unit(seed, agents[i], tick, (1 << 40) + (stream << 24) + j) - 1.0
