"""swarm.core.rng's draws in plain Python, for code that asks for a few numbers per
tick: the very same bits (tested against the compiled ones), without loading
numba into an agent process (88 MB) for three draws a tick."""

from __future__ import annotations

_M64 = (1 << 64) - 1
_GOLDEN = 0x9E3779B97F4A7C15
_TICK_MULT = 0xD1B54A32D192ED03
_M1 = 0xBF58476D1CE4E5B9
_M2 = 0x94D049BB133111EB
_TO_UNIT = 1.0 / 9007199254740992.0  # 2**-53


def mix64(z: int) -> int:
    z = ((z ^ (z >> 30)) * _M1) & _M64
    z = ((z ^ (z >> 27)) * _M2) & _M64
    return z ^ (z >> 31)


def draw_u64(seed: int, agent: int, tick: int, draw: int) -> int:
    h = mix64((seed + _GOLDEN * (agent + 1)) & _M64)
    return mix64(h ^ ((tick * _TICK_MULT + draw) & _M64))


def draw_unit(seed: int, agent: int, tick: int, draw: int) -> float:
    """A uniform float in [0, 1) from the top 53 bits of one draw (swarm.core.rng.draw_unit)."""
    return float(draw_u64(int(seed), int(agent), int(tick), int(draw)) >> 11) * _TO_UNIT
