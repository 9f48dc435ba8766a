"""All rays of all robots in one compiled pass, against walls and robot discs.

A uniform grid over the arena indexes the wall segments once (scheduled
obstacles are in it too, switched by a flag) and the robots' discs every tick
(a counting sort, O(robots)).  Each ray walks the grid cells it crosses in
order (Amanatides & Woo), tests only what those cells hold, and stops at the
first cell that contains its nearest hit: the cost follows the rays' actual
paths, not the size of the world.  A ray never sees its own robot's disc.
The rays come robot by robot: one compiled loop per run of a robot's rays
takes its heading's cosine and sine once and walks each ray with the hit tests
inlined; the parallel pass hands whole runs to the cores, so every ray is
still computed alone and any thread count reads the same bits.

Segments belong to layers: SOLID (walls, boxes: every sensor sees them) and
MARK (coloured marks that only cameras see, like the BG paper's dangerous
areas, which the animat sees and drives across).  `seg_on[s]` holds the layer
bits of segment s (0: not in the world now) and a ray sees what its mask shares.

Hits: `hit >= 0` is a segment index, `hit <= -2` is robot `-2 - hit`,
`-1` is nothing within range (range reported as the ray's maximum).
"""

from __future__ import annotations

import math
import os

import numba
import numpy as np
from numba import njit, prange

NO_HIT = -1
SOLID, MARK = 1, 2
_threads = 1  # of the sensing pass in this process (set_threads)
# The size of a pass from which the cores share it: below it, waking the sleeping threads (about 35 us on
# this 2-core machine) costs more than they save (docs/arena.md, "Every core").
PARALLEL_RAYS = 4096
PARALLEL_NORMALS = 8192


def set_threads(threads: int) -> int:
    """Cast the rays over `threads` cores (0: every core; 1: the serial pass).  Each ray is cast alone,
    so every count gives the same readings, bit for bit.  Returns the count in use."""
    global _threads
    _threads = numba.config.NUMBA_NUM_THREADS if threads == 0 else min(threads, numba.config.NUMBA_NUM_THREADS)
    if _threads > 1:
        # OpenMP's idle threads spin by default: on a host whose cores are busy with other processes
        # each parallel pass then waits out a scheduler slice (10-20 ms) for a spinning thread; asleep,
        # they wake in microseconds.  Read once, when numba first starts its threads (just below).
        os.environ.setdefault("OMP_WAIT_POLICY", "passive")
        numba.set_num_threads(_threads)
    return _threads


def threads() -> int:
    return _threads


def parallel(items: int, least: int) -> bool:
    """Whether a pass over `items` (rays, noise draws) runs over the cores: more than one is set, and
    there are at least `least` of them to pay for waking the threads."""
    return _threads > 1 and items >= least


def grid_shape(extent: tuple[float, float, float, float], cell: float) -> tuple[int, int]:
    x0, y0, x1, y1 = extent
    return max(1, math.ceil((x1 - x0) / cell)), max(1, math.ceil((y1 - y0) / cell))


@njit(cache=True)
def _cell_range(lo, hi, origin, cell, n):
    a = math.floor((lo - origin) / cell)
    b = math.floor((hi - origin) / cell)
    return max(a, 0), min(b, n - 1)


@njit(cache=True)
def fill_cells(boxes, use, x0, y0, cell, nx, ny, start, items):
    """CSR lists of the boxes (x_min, y_min, x_max, y_max) that touch each cell,
    for boxes with `use` set, into `start` (nx*ny+1,) and `items`.  Returns the
    number of items, or -needed when `items` is too small (nothing is filled)."""
    for c in range(nx * ny + 1):
        start[c] = 0
    total = 0
    for b in range(boxes.shape[0]):
        if use[b]:
            i0, i1 = _cell_range(boxes[b, 0], boxes[b, 2], x0, cell, nx)
            j0, j1 = _cell_range(boxes[b, 1], boxes[b, 3], y0, cell, ny)
            for j in range(j0, j1 + 1):
                for i in range(i0, i1 + 1):
                    start[j * nx + i + 1] += 1
                    total += 1
    if total > items.shape[0]:
        return -total
    for c in range(nx * ny):
        start[c + 1] += start[c]
    slot = start[:-1].copy()
    for b in range(boxes.shape[0]):
        if use[b]:
            i0, i1 = _cell_range(boxes[b, 0], boxes[b, 2], x0, cell, nx)
            j0, j1 = _cell_range(boxes[b, 1], boxes[b, 3], y0, cell, ny)
            for j in range(j0, j1 + 1):
                for i in range(i0, i1 + 1):
                    c = j * nx + i
                    items[slot[c]] = b
                    slot[c] += 1
    return total


def build_segment_index(segs: np.ndarray, x0: float, y0: float, cell: float, nx: int, ny: int):
    """CSR lists of segment indices per cell (a segment's thin bounding box,
    exact for the axis-aligned edges of rectangles): (start, items);
    coordinates in the same order come from segs[items]."""
    boxes = np.column_stack([np.minimum(segs[:, 0], segs[:, 2]), np.minimum(segs[:, 1], segs[:, 3]),
                             np.maximum(segs[:, 0], segs[:, 2]), np.maximum(segs[:, 1], segs[:, 3])])  # fmt: skip
    use = np.ones(len(segs), np.bool_)
    start = np.zeros(nx * ny + 1, np.int64)
    needed = -fill_cells(boxes, use, x0, y0, cell, nx, ny, start, np.zeros(0, np.int64))
    items = np.zeros(max(needed, 0), np.int64)
    fill_cells(boxes, use, x0, y0, cell, nx, ny, start, items)
    return start, items


def build_disc_index(xy, radius, present, x0, y0, cell, nx, ny, start, items, xyr) -> int:
    """CSR lists of robots per cell (their bounding squares) into the
    preallocated `start`, `items` and `xyr` (centre and radius in cell order,
    so a ray reads memory in sequence).  Returns the number of items, or
    -needed when `items` is too small."""
    boxes = np.column_stack([xy[:, 0] - radius, xy[:, 1] - radius, xy[:, 0] + radius, xy[:, 1] + radius])
    total = fill_cells(boxes, present, x0, y0, cell, nx, ny, start, items)
    if total > 0:
        picked = items[:total]
        xyr[:total, :2] = xy[picked]
        xyr[:total, 2] = radius[picked]
    return total


# error_model="numpy": a float division needs no zero test (every divisor is checked or nonzero), so
# the loops compile without the branches that would raise ZeroDivisionError; the arithmetic is the same.
@njit(cache=True, inline="always", error_model="numpy")
def hit_segment(ox, oy, dx, dy, ax, ay, bx, by):
    ex, ey = bx - ax, by - ay
    den = dx * ey - dy * ex
    if abs(den) < 1e-15:
        return np.inf
    wx, wy = ax - ox, ay - oy
    t = (wx * ey - wy * ex) / den
    s = (wx * dy - wy * dx) / den
    if t >= 0.0 and 0.0 <= s <= 1.0:
        return t
    return np.inf


@njit(cache=True, inline="always", error_model="numpy")
def hit_disc(ox, oy, dx, dy, cx, cy, r):
    wx, wy = cx - ox, cy - oy
    b = wx * dx + wy * dy
    c = wx * wx + wy * wy - r * r
    disc = b * b - c
    if disc < 0.0:
        return np.inf
    t = b - math.sqrt(disc)
    if t < 0.0:
        return np.inf
    return t


@njit(cache=True, inline="always", error_model="numpy")
def cast_one(ox, oy, dx, dy, rmax, me, mask, s_coords, s_ids, seg_on, s_start, d_xyr, d_ids, d_start,
             x0, y0, cell, nx, ny):  # fmt: skip
    """Nearest hit of one ray: (distance, what).  The cells' contents are kept
    in cell order (coordinates beside ids), so a ray reads memory in sequence."""
    px, py = ox - x0, oy - y0
    cx = min(max(math.floor(px / cell), 0), nx - 1)
    cy = min(max(math.floor(py / cell), 0), ny - 1)
    if dx > 0.0:
        step_x, t_x, dt_x = 1, ((cx + 1) * cell - px) / dx, cell / dx
    elif dx < 0.0:
        step_x, t_x, dt_x = -1, (cx * cell - px) / dx, -cell / dx
    else:
        step_x, t_x, dt_x = 0, np.inf, np.inf
    if dy > 0.0:
        step_y, t_y, dt_y = 1, ((cy + 1) * cell - py) / dy, cell / dy
    elif dy < 0.0:
        step_y, t_y, dt_y = -1, (cy * cell - py) / dy, -cell / dy
    else:
        step_y, t_y, dt_y = 0, np.inf, np.inf
    best, what = np.inf, NO_HIT
    while True:
        c = cy * nx + cx
        for k in range(s_start[c], s_start[c + 1]):
            if seg_on[s_ids[k]] & mask:
                t = hit_segment(ox, oy, dx, dy, s_coords[k, 0], s_coords[k, 1], s_coords[k, 2], s_coords[k, 3])
                if t < best:
                    best, what = t, s_ids[k]
        for k in range(d_start[c], d_start[c + 1]):
            r = d_ids[k]
            if r != me:
                t = hit_disc(ox, oy, dx, dy, d_xyr[k, 0], d_xyr[k, 1], d_xyr[k, 2])
                if t < best:
                    best, what = t, -2 - r
        t_exit = min(t_x, t_y)
        if best <= t_exit or t_exit > rmax:
            break
        if t_x < t_y:
            cx += step_x
            t_x += dt_x
            if cx < 0 or cx >= nx:
                break
        else:
            cy += step_y
            t_y += dt_y
            if cy < 0 or cy >= ny:
                break
    if best > rmax:
        return rmax, NO_HIT
    return best, what


@njit(cache=True, error_model="numpy")
def robot_runs(ray_robot):
    """Where each run of consecutive rays of one robot starts, and the end: the rays come robot by robot,
    so each run shares its robot's heading."""
    n = ray_robot.shape[0]
    count = 1 if n else 0
    for k in range(1, n):
        if ray_robot[k] != ray_robot[k - 1]:
            count += 1
    runs = np.empty(count + 1, np.int64)
    j = 0
    for k in range(n):
        if k == 0 or ray_robot[k] != ray_robot[k - 1]:
            runs[j] = k
            j += 1
    runs[count] = n
    return runs


@njit(cache=True, inline="always", error_model="numpy")
def _cast_run(first, end, pose, ray_robot, ray_cos, ray_sin, ray_range, ray_mask, s_coords, s_ids, seg_on, s_start,
              d_xyr, d_ids, d_start, x0, y0, cell, nx, ny, out_range, out_hit):  # fmt: skip
    """Rays first..end-1, all of one robot: its heading's cosine and sine are computed once."""
    r = ray_robot[first]
    ox, oy = pose[r, 0], pose[r, 1]
    ch, sh = math.cos(pose[r, 2]), math.sin(pose[r, 2])
    for k in range(first, end):
        dx = ch * ray_cos[k] - sh * ray_sin[k]
        dy = sh * ray_cos[k] + ch * ray_sin[k]
        out_range[k], out_hit[k] = cast_one(ox, oy, dx, dy, ray_range[k], r, ray_mask[k], s_coords, s_ids, seg_on,
                                            s_start, d_xyr, d_ids, d_start, x0, y0, cell, nx, ny)  # fmt: skip


@njit(cache=True, error_model="numpy")
def cast_rays(pose, ray_robot, ray_cos, ray_sin, ray_range, ray_mask, s_coords, s_ids, seg_on, s_start, d_xyr, d_ids,
              d_start, x0, y0, cell, nx, ny, out_range, out_hit):  # fmt: skip
    """Cast every ray: ray k leaves the centre of robot ray_robot[k] at the
    bearing whose cosine and sine are ray_cos[k], ray_sin[k] (from its heading)
    and reaches at most ray_range[k], seeing the layers of ray_mask[k]."""
    runs = robot_runs(ray_robot)
    for j in range(runs.shape[0] - 1):
        _cast_run(runs[j], runs[j + 1], pose, ray_robot, ray_cos, ray_sin, ray_range, ray_mask, s_coords, s_ids,
                  seg_on, s_start, d_xyr, d_ids, d_start, x0, y0, cell, nx, ny, out_range, out_hit)  # fmt: skip


@njit(cache=True, parallel=True, error_model="numpy")
def cast_rays_parallel(pose, ray_robot, ray_cos, ray_sin, ray_range, ray_mask, s_coords, s_ids, seg_on, s_start, d_xyr,
                       d_ids, d_start, x0, y0, cell, nx, ny, out_range, out_hit):  # fmt: skip
    """`cast_rays` over the cores, run by run of one robot's rays: every ray is cast alone, from the
    same heading cosine and sine, so the readings are the serial pass's, bit for bit."""
    runs = robot_runs(ray_robot)
    for j in prange(runs.shape[0] - 1):
        _cast_run(runs[j], runs[j + 1], pose, ray_robot, ray_cos, ray_sin, ray_range, ray_mask, s_coords, s_ids,
                  seg_on, s_start, d_xyr, d_ids, d_start, x0, y0, cell, nx, ny, out_range, out_hit)  # fmt: skip


@njit(cache=True)
def hit_colours(what, seg_rgb, robot_rgb, out):
    """The colour each ray's hit shows (`what`: a segment's index, or -2 - a robot's), black for no hit."""
    for i in range(what.shape[0]):
        w = what[i]
        for c in range(3):
            out[i, c] = seg_rgb[w, c] if w >= 0 else robot_rgb[-2 - w, c] if w <= -2 else 0


def brute_force(
    ox: float,
    oy: float,
    angle: float,
    rmax: float,
    me: int,
    segs: np.ndarray,
    seg_on: np.ndarray,
    xy: np.ndarray,
    radius: np.ndarray,
    mask: int = SOLID | MARK,
) -> tuple[float, int]:
    """Every segment and disc, numpy: the reference the index is tested against."""
    dx, dy = math.cos(angle), math.sin(angle)
    ex, ey = segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1]
    den = dx * ey - dy * ex
    wx, wy = segs[:, 0] - ox, segs[:, 1] - oy
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (wx * ey - wy * ex) / den
        s = (wx * dy - wy * dx) / den
    ok = ((seg_on & mask) != 0) & (np.abs(den) >= 1e-15) & (t >= 0) & (s >= 0) & (s <= 1)
    ts = np.where(ok, t, np.inf)
    cx, cy = xy[:, 0] - ox, xy[:, 1] - oy
    b = cx * dx + cy * dy
    disc = b * b - (cx * cx + cy * cy - radius**2)
    with np.errstate(invalid="ignore"):
        td = b - np.sqrt(disc)
    td = np.where((disc >= 0) & (td >= 0), td, np.inf)
    if len(td) > me >= 0:
        td[me] = np.inf
    best_s = int(np.argmin(ts)) if len(ts) else -1
    best_d = int(np.argmin(td)) if len(td) else -1
    t_s = ts[best_s] if best_s >= 0 else np.inf
    t_d = td[best_d] if best_d >= 0 else np.inf
    if min(t_s, t_d) > rmax:
        return rmax, NO_HIT
    return (float(t_s), best_s) if t_s <= t_d else (float(t_d), -2 - best_d)
