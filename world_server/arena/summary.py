"""The arena run's summary: the same keys in every runtime (each adds its own on top)."""

from __future__ import annotations

from typing import Any

import numpy as np

from world_server.arena.world import ArenaWorld


def arena_summary(world: ArenaWorld, wall_seconds: float, runtime: str) -> dict[str, Any]:
    """What a run of this world did, robot by robot (L_o as far as the runner has filled
    world.optimum in: swarm.engines.arena.fill_optimum)."""
    s = world.scenario
    robots = world.robot_summaries(world.optimum)
    goals = [r for r in robots if r["goal"] is not None]
    ratios = [r["path_ratio"] for r in robots if r["path_ratio"] is not None]
    return {
        "scenario": s.name,
        "kind": "arena",
        "controller": s.controller,
        "agents": len(robots),
        "seed": s.seed,
        "noise": s.noise.level,
        "runtime": runtime,
        "ticks": world.tick,
        "iterations": world.tick,
        # with goals: all reached; without (explorers): the run went its full length; survival: its rule ended it
        "finished": all(r["reached"] for r in goals)
        if goals
        else (world.tick >= s.max_ticks or (world.metabolism is not None and world.metabolism.done())),
        "reached": sum(r["reached"] for r in goals),
        "with_goal": len(goals),
        "sim_seconds": round(world.tick * s.control_period, 3),
        "wall_seconds": round(wall_seconds, 4),
        "ticks_per_second": round(world.tick / wall_seconds, 1) if wall_seconds else None,
        "mean_path_ratio": round(float(np.mean(ratios)), 4) if ratios else None,
        "collisions": int(world.bodies.collisions.sum()),
        "rejected_actions": sum(world.rejected.values()),
        "rejected": dict(world.rejected),
        "robots": robots,
    }
