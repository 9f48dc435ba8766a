"""The reference `swarm bench arena` measures the ray pass against: every ray tested against every
segment and every disc, compiled like the pass and with its hit tests, but with no grid."""

from __future__ import annotations

import math
import time
from statistics import median

import numpy as np
from numba import njit

from world_server.arena.raycast import NO_HIT, hit_disc, hit_segment
from world_server.arena.world import ArenaWorld


@njit(cache=True, error_model="numpy")
def brute_rays(pose, ray_robot, ray_cos, ray_sin, ray_range, ray_mask, segs, seg_on, radius, present,
               out_range, out_hit):  # fmt: skip
    """Nearest hit of every ray over all segments and all discs (a ray never sees its own robot)."""
    for k in range(ray_robot.shape[0]):
        r = ray_robot[k]
        ch, sh = math.cos(pose[r, 2]), math.sin(pose[r, 2])
        dx = ch * ray_cos[k] - sh * ray_sin[k]
        dy = sh * ray_cos[k] + ch * ray_sin[k]
        ox, oy = pose[r, 0], pose[r, 1]
        best, what = np.inf, NO_HIT
        for s in range(segs.shape[0]):
            if seg_on[s] & ray_mask[k]:
                t = hit_segment(ox, oy, dx, dy, segs[s, 0], segs[s, 1], segs[s, 2], segs[s, 3])
                if t < best:
                    best, what = t, s
        for d in range(pose.shape[0]):
            if present[d] and d != r:
                t = hit_disc(ox, oy, dx, dy, pose[d, 0], pose[d, 1], radius[d])
                if t < best:
                    best, what = t, -2 - d
        out_range[k], out_hit[k] = (ray_range[k], NO_HIT) if best > ray_range[k] else (best, what)


def time_passes(world: ArenaWorld, repeats: int) -> dict:
    """Median ms of the brute-force reference and of the grid's ray pass (`ArenaWorld.cast`, one
    thread; wall and CPU time) over the same rays of the world's first suite, timed in turns; and how many rays of
    the two agree on the distance to 1e-9 m (corners hit at one distance may name either edge)."""
    robot, bearing, max_range, c, s, mask = world.suites[0].rays(world.tick)
    ranges, what = np.empty(len(robot)), np.empty(len(robot), np.int64)
    args = (world.pose, robot.astype(np.int64), c, s, max_range, mask, world.segs, world.seg_on, world.radius,
            world.in_world, ranges, what)  # fmt: skip
    brute_rays(*args)
    world.cast(robot, bearing, max_range, (c, s), mask)
    brute, grid, grid_cpu = [], [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        brute_rays(*args)
        t1, c1 = time.perf_counter(), time.process_time()
        grid_ranges, _ = world.cast(robot, bearing, max_range, (c, s), mask)
        t2, c2 = time.perf_counter(), time.process_time()
        brute.append(t1 - t0)
        grid.append(t2 - t1)
        grid_cpu.append(c2 - c1)
    agree = int(np.sum(np.abs(grid_ranges - ranges) <= 1e-9))
    return {"rays": len(robot), "brute_ms": round(1000 * median(brute), 3), "pass_ms": round(1000 * median(grid), 3),
            "pass_cpu_ms": round(1000 * median(grid_cpu), 3), "agree": agree}  # fmt: skip
