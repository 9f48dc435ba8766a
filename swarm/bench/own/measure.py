"""`swarm bench own`: what loading a controller by "module:Class" costs a run in process (and, in
grid.py, a grid controller's step loaded from outside beside the bundled one).

wander's own module is copied into a temporary folder outside the package and run as
"copied_wander:WanderController" on the Z-maze, beside the registered `wander`, with the same
robots and seed; rounds alternate the two (the machine's speed drifts) and each row is the
median of its rounds.  The poses of the two runs are compared too: the copy must drive the same."""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path
from statistics import median

from swarm.bench.own.grid import bench_grid, format_grid, write_copy

SCENARIO = "zmaze"
COPY = "copied_wander"


def _engine(controller: str, robots: int, ticks: int):
    from swarm.engines.arena import ArenaEngine
    from swarm.scenario import load_scenario

    return ArenaEngine(load_scenario(SCENARIO).with_overrides(controller=controller, agents=robots, max_ticks=ticks))


def _timed(controller: str, robots: int, ticks: int):
    engine = _engine(controller, robots, ticks)
    engine.step(5)  # kernels loaded, first-tick work done
    t0 = time.perf_counter()
    engine.step(ticks)
    return time.perf_counter() - t0, engine.world.pose.copy()


def bench_own(quick: bool = False) -> dict:
    import importlib.util

    from agents.controllers import CONTROLLERS

    source = Path(importlib.util.find_spec(CONTROLLERS["wander"].factory.partition(":")[0]).origin)
    robots, ticks, rounds = (10, 200, 3) if quick else (10, 2000, 7)
    with tempfile.TemporaryDirectory(prefix="swarm-own-") as folder:
        (Path(folder) / f"{COPY}.py").write_text(source.read_text())
        write_copy(Path(folder))
        sys.path.insert(0, folder)
        try:
            times: dict[str, list[float]] = {"wander": [], f"{COPY}:WanderController": []}
            poses = {}
            for _ in range(rounds):
                for name in times:
                    seconds, poses[name] = _timed(name, robots, ticks)
                    times[name].append(seconds)
            grid = bench_grid(quick)
        finally:
            sys.path.remove(folder)
    registered, loaded = (median(v) for v in times.values())
    same = all((poses["wander"] == p).all() for p in poses.values())
    return {"scenario": SCENARIO, "robots": robots, "ticks": ticks, "rounds": rounds,
            "registered_ticks_per_s": ticks / registered, "loaded_ticks_per_s": ticks / loaded,
            "slowdown": loaded / registered - 1.0, "same_poses": bool(same), "grid": grid}  # fmt: skip


def format_own_bench(r: dict) -> str:
    return (
        f"{r['robots']} wander robots on {r['scenario']}, {r['ticks']} ticks, median of {r['rounds']} rounds each:\n"
        f"  registered   wander                           {r['registered_ticks_per_s']:8.1f} ticks/s\n"
        f"  module:Class {COPY}:WanderController  {r['loaded_ticks_per_s']:8.1f} ticks/s\n"
        f"  loaded by module:Class: {100 * r['slowdown']:+.1f}% time (target: at most +5%); "
        f"poses {'identical' if r['same_poses'] else 'DIFFER'}\n" + format_grid(r["grid"])
    )
