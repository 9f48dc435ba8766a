"""Sensor noise over the cores, for a world that senses with more than one thread."""

from numba import njit, prange

from swarm.core.rng import normal_row


@njit(cache=True, parallel=True)
def fill_normal_parallel(seed, agents, tick, stream, out):
    """swarm.core.rng.fill_normal with its rows over the cores: each row depends on its agent alone,
    so the numbers are the same, bit for bit."""
    for i in prange(out.shape[0]):
        normal_row(seed, agents[i], tick, stream, out[i])
