"""Counter-based random numbers keyed by (seed, agent, tick, draw).

A draw depends only on who asks, when, and which draw it is, never on the order
in which agents are stepped.  That is what lets one agent process, alone on its
machine, make exactly the choices it would make inside the in-process engine.
"""

import numpy as np
from numba import njit

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
