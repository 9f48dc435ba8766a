"""Algorithm 1 of the paper (Barraquand's wavefront): BFS distances from the base.

It is the ground truth the agents' marks converge to (Theorem 3.1), and it
tells the scenario generator which cells the base can reach.
"""

import numpy as np
from numba import njit

UNREACHABLE = -1


@njit(cache=True)
def bfs_distances(obstacles, base_r, base_c):
    """4-neighbour BFS distance of every cell from the base; -1 if unreachable."""
    h, w = obstacles.shape
    dist = np.full((h, w), UNREACHABLE, dtype=np.int64)
    queue = np.empty(h * w, dtype=np.int64)
    dist[base_r, base_c] = 0
    queue[0] = base_r * w + base_c
    head = 0
    tail = 1
    while head < tail:
        cell = queue[head]
        head += 1
        r = cell // w
        c = cell % w
        for dr, dc in ((-1, 0), (0, 1), (1, 0), (0, -1)):
            nr = r + dr
            nc = c + dc
            if 0 <= nr < h and 0 <= nc < w and not obstacles[nr, nc] and dist[nr, nc] < 0:
                dist[nr, nc] = dist[r, c] + 1
                queue[tail] = nr * w + nc
                tail += 1
    return dist
