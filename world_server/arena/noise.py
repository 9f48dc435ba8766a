"""Sensor noise in compiled loops: over the cores, for a world that senses with more than one thread, and
added to a laser's ranges."""

import numpy as np
from numba import njit, prange

from swarm.core.rng import normal_row


@njit(cache=True, parallel=True)
def fill_normal_parallel(seed, agents, tick, stream, out):
    """swarm.core.rng.fill_normal with its rows over the cores: each row depends on its agent alone,
    so the numbers are the same, bit for bit."""
    for i in prange(out.shape[0]):
        normal_row(seed, agents[i], tick, stream, out[i])


@njit(cache=True)
def noisy_ranges(scan: np.ndarray, normal: np.ndarray, std: float, factor: float, reach: float,
                 out: np.ndarray) -> None:  # fmt: skip
    """Each beam's range plus its error, clipped to [0, reach]; a beam that met nothing reads `reach`.
    One pass instead of numpy's four arrays, the same operations in the same order: the same bits."""
    for i in range(scan.shape[0]):
        for j in range(scan.shape[1]):
            if scan[i, j] >= reach:
                out[i, j] = reach
            else:
                out[i, j] = min(max(scan[i, j] + normal[i, j] * std * factor, 0.0), reach)
