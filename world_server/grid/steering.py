"""Where a physical body drives within a tick (world_server/grid/bodies.py).

A body drives straight to the centre of its target cell when it is in that
cell or next to it, the usual case: the straight line then stays inside free
cells.  A body the crowd pushed farther away (around a corner, down a
corridor) would drive into a wall and stay there; it follows the grid instead,
to the neighbouring cell one step closer to its target.  The step comes from
the wavefront's BFS in a window of `WINDOW` cells around the target: a body
pushed farther than that drives straight, as before.
"""

from numba import njit

from world_server.grid.wavefront import bfs_distances

WINDOW = 8  # cells each way around the target that the BFS covers
_DR = (-1, 0, 1, 0)
_DC = (0, 1, 0, -1)


@njit(cache=True)
def waypoints(xy, target, obstacles, out):
    """Fill `out` (n, 2) with the point each body drives to now (x, y in cells)."""
    h, w = obstacles.shape
    for a in range(xy.shape[0]):
        tr, tc = target[a, 0], target[a, 1]
        out[a, 0], out[a, 1] = tc + 0.5, tr + 0.5
        r = min(max(int(xy[a, 1]), 0), h - 1)  # int() floors here: what it rounds up, below 0, is clipped
        c = min(max(int(xy[a, 0]), 0), w - 1)
        if abs(r - tr) + abs(c - tc) <= 1 or abs(r - tr) > WINDOW or abs(c - tc) > WINDOW or obstacles[r, c]:
            continue
        r0, c0 = max(tr - WINDOW, 0), max(tc - WINDOW, 0)
        dist = bfs_distances(obstacles[r0 : tr + WINDOW + 1, c0 : tc + WINDOW + 1], tr - r0, tc - c0)
        here = dist[r - r0, c - c0]
        if here < 0:  # not connected within the window: straight, as before
            continue
        for k in range(4):
            nr, nc = r - r0 + _DR[k], c - c0 + _DC[k]
            if 0 <= nr < dist.shape[0] and 0 <= nc < dist.shape[1] and dist[nr, nc] == here - 1:
                out[a, 0], out[a, 1] = nc + c0 + 0.5, nr + r0 + 0.5
                break
