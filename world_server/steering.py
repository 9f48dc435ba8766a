"""Where a physical body drives within a tick (world_server/bodies.py).

A body drives straight to the centre of its target cell when it is in that
cell or next to it, the usual case: the straight line then stays inside free
cells.  A body the crowd pushed farther away (around a corner, down a
corridor) would drive into a wall and stay there; it follows the grid instead,
to the neighbouring cell one step closer to its target.  The step comes from a
BFS in a window of `WINDOW` cells around the target: a body pushed farther than
that drives straight, as before.
"""

import numpy as np
from numba import njit

WINDOW = 8  # cells each way around the target that the BFS covers
_DR = (-1, 0, 1, 0)
_DC = (0, 1, 0, -1)


@njit(cache=True)
def waypoints(xy, target, obstacles, out):
    """Fill `out` (n, 2) with the point each body drives to now (x, y in cells)."""
    h, w = obstacles.shape
    side = 2 * WINDOW + 1
    dist = np.empty((side, side), dtype=np.int64)
    queue = np.empty(side * side, dtype=np.int64)
    for a in range(xy.shape[0]):
        tr, tc = target[a, 0], target[a, 1]
        out[a, 0], out[a, 1] = tc + 0.5, tr + 0.5
        r = min(max(int(np.floor(xy[a, 1])), 0), h - 1)
        c = min(max(int(np.floor(xy[a, 0])), 0), w - 1)
        if abs(r - tr) + abs(c - tc) <= 1 or abs(r - tr) > WINDOW or abs(c - tc) > WINDOW or obstacles[r, c]:
            continue
        # BFS from the target over free cells of the window, until it reaches the body's cell
        dist[:] = -1
        r0, c0 = tr - WINDOW, tc - WINDOW
        dist[WINDOW, WINDOW] = 0
        queue[0] = WINDOW * side + WINDOW
        head, tail = 0, 1
        while head < tail and dist[r - r0, c - c0] < 0:
            cell = queue[head]
            head += 1
            lr, lc = cell // side, cell % side
            for k in range(4):
                nr, nc = lr + _DR[k], lc + _DC[k]
                gr, gc = nr + r0, nc + c0
                if 0 <= nr < side and 0 <= nc < side and 0 <= gr < h and 0 <= gc < w:
                    if dist[nr, nc] < 0 and not obstacles[gr, gc]:
                        dist[nr, nc] = dist[lr, lc] + 1
                        queue[tail] = nr * side + nc
                        tail += 1
        here = dist[r - r0, c - c0]
        if here < 0:  # not connected within the window: straight, as before
            continue
        for k in range(4):
            nr, nc = r - r0 + _DR[k], c - c0 + _DC[k]
            if 0 <= nr < side and 0 <= nc < side and dist[nr, nc] == here - 1:
                out[a, 0], out[a, 1] = nc + c0 + 0.5, nr + r0 + 0.5
                break
