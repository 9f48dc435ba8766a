"""A* on an 8-neighbour occupancy grid with clearance, as the DFT paper's
reference optimum L_o: 1 cm cells, a cell is usable only when no wall cell lies
within the clearance (4 cm) - except near the start and the goal, where the
original code waives the test - steps of 1 or sqrt(2) cells, Euclidean length.

Ours is exact A* (octile heuristic, consistent, cells may be re-opened), where
the original code stopped at the first chain that reached the start; our L_o is
therefore never longer than theirs (docs/arena.md).

The search is a compiled kernel (swarm.core.kernels): the JIT's in process, the
agents' ahead-of-time build in agent processes, which then run without numba.
"""

from __future__ import annotations

import math

import numpy as np

from swarm.core.kernels import exported, njit

SQRT2 = math.sqrt(2.0)


def occupancy(size: tuple[float, float], cell: float, rects: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """Boolean grid [row j (y), col i (x)], True where a wall touches the cell."""
    nx, ny = math.ceil(size[0] / cell - 1e-9), math.ceil(size[1] / cell - 1e-9)
    occ = np.zeros((ny, nx), np.bool_)
    for x0, y0, x1, y1 in np.asarray(rects, np.float64).reshape(-1, 4):
        i0, i1 = max(math.floor(x0 / cell + 1e-9), 0), min(math.ceil(x1 / cell - 1e-9), nx)
        j0, j1 = max(math.floor(y0 / cell + 1e-9), 0), min(math.ceil(y1 / cell - 1e-9), ny)
        occ[j0:j1, i0:i1] = True
    for x0, y0, x1, y1 in np.asarray(segments, np.float64).reshape(-1, 4):
        n = max(2, int(math.hypot(x1 - x0, y1 - y0) / (cell / 4)) + 2)
        xs, ys = np.linspace(x0, x1, n), np.linspace(y0, y1, n)
        occ[np.clip((ys / cell).astype(int), 0, ny - 1), np.clip((xs / cell).astype(int), 0, nx - 1)] = True
    return occ


def wall_distance(occ: np.ndarray, up_to: float) -> np.ndarray:
    """Distance in cells from every cell to the nearest wall cell (or the grid's
    edge), exact up to `up_to`, inf beyond: the clearance test needs no more.
    Numpy over the disc's offsets, not scipy's transform (25 MB in an agent)."""
    reach = math.floor(up_to)
    ny, nx = occ.shape
    padded = np.pad(occ, reach + 1, constant_values=True)
    d2 = np.full(occ.shape, np.inf)
    for dj in range(-reach - 1, reach + 2):
        for di in range(-reach - 1, reach + 2):
            r2 = float(di * di + dj * dj)
            if r2 <= (reach + 1) ** 2:
                wall = padded[reach + 1 + dj : reach + 1 + dj + ny, reach + 1 + di : reach + 1 + di + nx]
                np.minimum(d2, np.where(wall, r2, np.inf), out=d2)
    dist = np.sqrt(d2)
    dist[dist > up_to] = np.inf
    return dist


@exported("astar", "Tuple((float64, int64[::1]))(boolean[:, :], int64, int64, int64, int64)")
@njit(cache=True)
def astar_cells(free, si, sj, gi, gj):
    ny, nx = free.shape
    inf = np.inf
    g = np.full(ny * nx, inf)
    parent = np.full(ny * nx, -1, np.int64)
    closed = np.zeros(ny * nx, np.bool_)
    heap_f = np.empty(16, np.float64)
    heap_i = np.empty(16, np.int64)
    size = 0
    start, goal = sj * nx + si, gj * nx + gi
    g[start] = 0.0

    def h(c):
        dx, dy = abs(c % nx - gi), abs(c // nx - gj)
        return (dx + dy) + (SQRT2 - 2.0) * min(dx, dy)

    # heap push (start)
    heap_f[0], heap_i[0], size = h(start), start, 1
    di = (1, -1, 0, 0, 1, 1, -1, -1)
    dj = (0, 0, 1, -1, 1, -1, 1, -1)
    while size > 0:
        c = heap_i[0]
        # pop
        size -= 1
        lf, li = heap_f[size], heap_i[size]
        k = 0
        while True:
            a = 2 * k + 1
            if a >= size:
                break
            if a + 1 < size and heap_f[a + 1] < heap_f[a]:
                a += 1
            if heap_f[a] >= lf:
                break
            heap_f[k], heap_i[k] = heap_f[a], heap_i[a]
            k = a
        if size > 0:
            heap_f[k], heap_i[k] = lf, li
        if closed[c]:
            continue
        closed[c] = True
        if c == goal:
            break
        ci, cj = c % nx, c // nx
        for m in range(8):
            ni, nj = ci + di[m], cj + dj[m]
            if ni < 0 or nj < 0 or ni >= nx or nj >= ny or not free[nj, ni]:
                continue
            if m >= 4 and not (free[cj, ni] and free[nj, ci]):
                continue  # no diagonal through a blocked corner
            n = nj * nx + ni
            cost = g[c] + (SQRT2 if m >= 4 else 1.0)
            if cost < g[n]:
                g[n] = cost
                parent[n] = c
                if size == heap_f.shape[0]:
                    heap_f = np.concatenate((heap_f, np.empty(size, np.float64)))
                    heap_i = np.concatenate((heap_i, np.empty(size, np.int64)))
                # push
                k = size
                size += 1
                f = cost + h(n)
                while k > 0:
                    p = (k - 1) // 2
                    if heap_f[p] <= f:
                        break
                    heap_f[k], heap_i[k] = heap_f[p], heap_i[p]
                    k = p
                heap_f[k], heap_i[k] = f, n
    return g[goal], parent


class Planner:
    """A* over one map at one resolution; plans between points in metres."""

    def __init__(self, size: tuple[float, float], rects: np.ndarray, segments: np.ndarray,
                 cell: float = 0.01, clearance: float = 0.04):  # fmt: skip
        self.size, self.cell, self.clearance = size, cell, clearance
        self.occ = occupancy(size, cell, rects, segments)
        self.dist = wall_distance(self.occ, clearance / cell + 1.0)
        self.clear_cells = clearance / cell

    def cell_of(self, x: float, y: float) -> tuple[int, int]:
        ny, nx = self.occ.shape
        return min(max(int(x / self.cell), 0), nx - 1), min(max(int(y / self.cell), 0), ny - 1)

    def _free(self, a: tuple[int, int], b: tuple[int, int]) -> np.ndarray:
        free = self.dist > self.clear_cells
        ny, nx = self.occ.shape
        jj, ii = np.ogrid[:ny, :nx]
        for ci, cj in (a, b):
            free |= ((ii - ci) ** 2 + (jj - cj) ** 2 <= self.clear_cells**2) & ~self.occ
        return free

    def plan(self, start: tuple[float, float], goal: tuple[float, float]) -> tuple[float, np.ndarray]:
        """(length in metres, path points (k, 2) from start to goal, cell centres);
        (inf, empty) when no path keeps the clearance."""
        a, b = self.cell_of(*start), self.cell_of(*goal)
        free = self._free(a, b)
        if not (free[a[1], a[0]] and free[b[1], b[0]]):
            return math.inf, np.zeros((0, 2))
        cost, parent = astar_cells(free, a[0], a[1], b[0], b[1])
        if not math.isfinite(cost):
            return math.inf, np.zeros((0, 2))
        nx = self.occ.shape[1]
        chain = [b[1] * nx + b[0]]
        while chain[-1] != a[1] * nx + a[0]:
            chain.append(int(parent[chain[-1]]))
        cells = np.array(chain[::-1], np.int64)
        points = np.column_stack([(cells % nx + 0.5) * self.cell, (cells // nx + 0.5) * self.cell])
        return float(cost) * self.cell, points
