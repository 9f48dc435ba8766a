"""`swarm bench arena`: what sensing and physics cost in the arena, and how
the cost grows with robots and with walls.

The world: a 20 x 20 m walled arena with 100 rectangular
obstacles (sides 0.3-1.5 m, seeded), robots of 0.2 m radius placed on a
jittered lattice clear of the obstacles, driving forward with a slight turn
(so they meet walls and each other).  Two sensor suites: the animat's
(36-sector camera, one ray a sector, 8 sonars of 3 rays) and a 64-beam 360-degree
laser.  Sensing is the whole `perceive` (ray pass and read-outs, noise
included); physics is one 64 ms control period of pymunk (4 substeps).  The
e-puck row is the whole tick for 100 e-pucks in the same world.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace
from statistics import median

import numpy as np

from swarm.bench.arena.brute import time_passes
from world_server.arena.face.robots import ANIMAT, EPUCK, RobotModel
from world_server.arena.face.sensors import Sensors
from world_server.arena.face.sensors.laser import Laser
from world_server.arena.scenario import ArenaScenario, Group, Wall
from world_server.arena.world import ArenaWorld

SIDE = 20.0
LASER_BOT = RobotModel("laser64", 0.2, 0.3, 0.5, 0.5, 1.0, sensors=Sensors(laser=Laser(beams=64, range=8.0)))


def bench_world(robots: int, model: RobotModel, obstacles: int = 100, seed: int = 1, side: float = SIDE,
                strips: int = 1) -> ArenaWorld:  # fmt: skip
    rng = np.random.default_rng([seed, 0xBE4C])
    walls = [Wall("rect", (0.0, 0.0, side, 0.1)), Wall("rect", (0.0, side - 0.1, side, side)),
             Wall("rect", (0.0, 0.0, 0.1, side)), Wall("rect", (side - 0.1, 0.0, side, side))]  # fmt: skip
    rects = []
    for _ in range(obstacles):
        w, h = rng.uniform(0.3, 1.5, 2)
        x, y = rng.uniform(0.2, side - 0.2 - w), rng.uniform(0.2, side - 0.2 - h)
        rects.append((x, y, x + w, y + h))
        walls.append(Wall("rect", rects[-1], (int(rng.integers(30, 255)),) * 3))
    starts = _lattice(robots, model.radius, np.array(rects).reshape(-1, 4), rng, side)
    group = Group(robots, "carrot", model, tuple(map(tuple, starts)), 0.0)
    s = ArenaScenario("bench", "bench", (side, side), (group,), tuple(walls), seed=seed, max_ticks=10**9,
                      physics_strips=strips)  # fmt: skip
    return ArenaWorld(s)


def _lattice(n: int, radius: float, rects: np.ndarray, rng, side: float) -> np.ndarray:
    from world_server.arena.scenario import clearance_at

    spacing = 1.5
    while True:
        g = np.arange(0.3, side - 0.3, spacing)
        xy = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
        xy = xy + rng.uniform(-0.05, 0.05, xy.shape) * min(spacing - 2 * radius, 0.1) * 10
        free = xy[clearance_at(xy, rects, np.zeros((0, 4))) > radius + 0.02]
        if len(free) >= n or spacing < 2 * radius + 0.05:
            break
        spacing *= 0.95
    if len(free) < n:
        raise ValueError(f"only {len(free)} places for {n} robots")
    pick = free[rng.choice(len(free), n, replace=False)]
    return np.column_stack([pick, rng.uniform(0, 2 * math.pi, n)])


def _measure(world: ArenaWorld, ticks: int) -> dict:
    n = world.n
    turn = np.linspace(-0.2, 0.2, n) * world.max_wheel
    wheels = np.column_stack([0.8 * world.max_wheel - turn, 0.8 * world.max_wheel + turn]) * 0.5
    world.perceive_groups()  # compile / warm
    world.apply(wheels)
    senses, physics_times, cpu = [], [], []
    for _ in range(ticks):
        t0, c0 = time.perf_counter(), time.process_time()
        world.perceive_groups()
        t1, c1 = time.perf_counter(), time.process_time()
        world.apply(wheels)
        t2 = time.perf_counter()
        senses.append(t1 - t0)
        cpu.append(c1 - c0)
        physics_times.append(t2 - t1)
    # per tick, medians: a shared machine's hiccups land in single ticks, and the big worlds run only a few dozen
    sense, physics = median(senses), median(physics_times)
    rays = n * sum(s.per_robot for s in world.suites) // max(len(world.suites), 1)
    tick = sense + physics
    return {
        "robots": n,
        "rays_per_tick": rays,
        "sense_ms": round(1000 * sense, 3),
        "physics_ms": round(1000 * physics, 3),
        "ticks_per_second": round(1 / tick, 1),
        "robot_steps_per_second": round(n / tick),
        "rays_per_second": round(rays / sense) if sense else None,
        # CPU time of every thread: what sensing costs the cores, whoever else shares them
        "sense_cpu_ms": round(1000 * median(cpu), 3),
        "rays_per_cpu_second": round(rays / median(cpu)) if median(cpu) else None,
    }


def _ticks_for(robots: int, quick: bool) -> int:
    base = 20 if quick else 60
    return max(10 if quick else 30, int(base * 100 / max(robots, 100) * (10 if robots <= 10 else 1)))


def bench_arena(quick: bool = False) -> dict:
    from tqdm import tqdm

    sizes = (1, 10, 100, 1000)
    suites = {"animat": replace(ANIMAT, radius=0.2), "laser64": LASER_BOT}
    jobs = [(name, n) for name in suites for n in sizes]
    rows, bar = [], tqdm(total=len(jobs) + 4 + 3, desc="bench arena", unit="world", leave=False)
    for name, n in jobs:
        rows.append({"suite": name, **_measure(bench_world(n, suites[name]), _ticks_for(n, quick))})
        bar.update()
    walls = []
    for obstacles in (0, 50, 100, 200):
        walls.append({"obstacles": obstacles,
                      **_measure(bench_world(100, LASER_BOT, obstacles=obstacles), 10 if quick else 30)})  # fmt: skip
        bar.update()
    epuck = {"suite": "epuck", **_measure(bench_world(100, EPUCK), 100 if quick else 500)}
    bar.update()
    cores = _cores(quick)
    bar.update()
    reference = time_passes(bench_world(1000, LASER_BOT), 3 if quick else 7)
    bar.update()
    bar.close()
    return {"world": f"{SIDE:g} x {SIDE:g} m, 100 obstacles 0.3-1.5 m, robots r = 0.2 m (e-pucks 37 mm)",
            "rows": rows, "walls": walls, "epuck100": epuck, "cores": cores, "reference": reference}  # fmt: skip


def _cores(quick: bool) -> list[dict]:
    """Laser robots on one core and on every core (`--threads 0`), 1000 and 10,000 of them (the 10,000
    with 1000 obstacles in a 63 m square: as dense as the 1000 in 20 m; not with --quick), and on every
    core with their floor in a physics strip per core (as many as fit: a strip is at least its halo
    wide), each strip's space stepped on a core of its own."""
    import numba

    from world_server.arena import raycast

    rows = []
    for n in (1000,) if quick else (1000, 10_000):
        side = SIDE * math.sqrt(n / 1000)
        one = bench_world(n, LASER_BOT, obstacles=n // 10, side=side)  # its halo says how many strips fit
        strips = min(numba.config.NUMBA_NUM_THREADS, 64, int(side / one.scenario.physics_halo()))
        for threads, k in [(1, 1), (0, 1)] + ([(0, strips)] if strips > 1 else []):
            # a fresh world each: the same start, not one run on
            world = one if threads == 1 else bench_world(n, LASER_BOT, obstacles=n // 10, side=side, strips=k)
            try:
                used = raycast.set_threads(threads)
                rows.append({"robots": n, "threads": used, "strips": k, **_measure(world, 10 if quick else 30)})
            finally:
                raycast.set_threads(1)
    return rows


def format_arena_bench(result: dict) -> str:
    head = "| suite | robots | rays/tick | sensing ms | physics ms | ticks/s | robot-steps/s | rays/s |"
    lines = [f"swarm bench arena: {result['world']}, one core", "", head, "|---|---|---|---|---|---|---|---|"]
    for r in [*result["rows"], result["epuck100"]]:
        lines.append(
            f"| {r['suite']} | {r['robots']} | {r['rays_per_tick']} | {r['sense_ms']} | {r['physics_ms']} | "
            f"{r['ticks_per_second']} | {r['robot_steps_per_second']:,} | {r['rays_per_second'] or 0:,} |"
        )
    lines += ["", "Walls (100 laser robots): how sensing grows with obstacles", "",
              "| obstacles | sensing ms | rays/s | physics ms |", "|---|---|---|---|"]  # fmt: skip
    for r in result["walls"]:
        lines.append(f"| {r['obstacles']} | {r['sense_ms']} | {r['rays_per_second']:,} | {r['physics_ms']} |")
    laser = next(r for r in result["rows"] if r["suite"] == "laser64" and r["robots"] == 1000)
    e = result["epuck100"]
    lines += ["", "Laser robots on one core and on every core (--threads 0), the floor in one physics strip or in a "
              "strip per core; speed-ups against one thread and one strip; CPU: all threads' time of the sensing", "",
              "| robots | threads | strips | sensing ms | speed-up | physics ms | speed-up | ticks/s | rays/s | CPU ms "
              "| rays/CPU-s |", "|---|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    one = {r["robots"]: r for r in result["cores"] if r["threads"] == 1 and r["strips"] == 1}
    for r in result["cores"]:
        base = one[r["robots"]]
        lines.append(f"| {r['robots']:,} | {r['threads']} | {r['strips']} | {r['sense_ms']} | "
                     f"{base['sense_ms'] / r['sense_ms']:.2f} | {r['physics_ms']} | "
                     f"{base['physics_ms'] / r['physics_ms']:.2f} | {r['ticks_per_second']} | "
                     f"{r['rays_per_second']:,} | {r['sense_cpu_ms']} | "
                     f"{r['rays_per_cpu_second'] or 0:,} |")  # fmt: skip
    lines += _reference_lines(result["reference"], result["cores"])
    lines += ["", f"targets: 1000 robots x 64-beam laser sensing {laser['sense_ms']} ms/tick (target <= 10 ms); "
              f"100 e-pucks whole tick {e['ticks_per_second']} ticks/s (target >= 500)"]  # fmt: skip
    return "\n".join(lines)


def _reference_lines(ref: dict, cores: list[dict]) -> list[str]:
    """The brute-force reference against the ray pass and against the whole sensing (noise and
    read-outs included) of the cores table's 1000 robots."""
    out = ["", f"Brute force (every ray against every segment and disc, compiled, one core) over the "
           f"{ref['rays']:,} rays of 1000 laser robots: {ref['brute_ms']} ms; the grid's ray pass, timed in turns "
           f"with it: {ref['pass_ms']} ms ({ref['brute_ms'] / ref['pass_ms']:.1f}x; {ref['agree']:,} rays at the same "
           f"distance); the pass's CPU time {ref['pass_cpu_ms']} ms, "
           f"{ref['rays'] / ref['pass_cpu_ms'] / 1e3:.1f} M rays per CPU-second"]  # fmt: skip
    for r in (r for r in cores if r["robots"] == 1000 and r["strips"] == 1):
        out.append(f"- sensing on {r['threads']} thread(s), {r['sense_ms']} ms: {ref['brute_ms'] / r['sense_ms']:.1f}x "
                   "the brute force")  # fmt: skip
    return out
