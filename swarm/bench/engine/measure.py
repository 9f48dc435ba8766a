"""`swarm bench engine`: agent-steps per second of the in-process engine.

Whole runs to completion (not a synthetic loop), one core, compiled code
warmed up first.  Also reports how throughput scales with agents and grid.
"""

from __future__ import annotations

import time

from swarm.engines.grid import Engine
from swarm.scenario import load_scenario


def _throughput(scenario_ref: str, agents: int, min_seconds: float, controller: str = "cmarking"):
    steps = 0
    seconds = 0.0
    runs = 0
    seed = 0
    while seconds < min_seconds or runs < 3:
        scenario = load_scenario(scenario_ref).with_overrides(agents=agents, seed=seed, controller=controller)
        engine = Engine(scenario)
        started = time.perf_counter()
        engine.run("foraged", 1_000_000)
        seconds += time.perf_counter() - started
        steps += engine.tick * agents
        runs += 1
        seed += 1
    return {"scenario": scenario_ref, "agents": agents, "controller": controller, "runs": runs,
            "agent_steps": steps, "seconds": round(seconds, 3),
            "agent_steps_per_second": round(steps / seconds)}  # fmt: skip


def bench_engine(quick: bool = False) -> dict:
    # Warm the compiled kernels (the disk cache makes this cheap after the first time).
    Engine(load_scenario("setup2").with_overrides(seed=0)).run("foraged", 10_000)
    t = 0.5 if quick else 2.0
    headline = [_throughput("setup1", n, t) for n in (20, 160)]
    scaling_agents = [_throughput("setup1", n, t / 2) for n in (5, 40, 640)]
    scaling_grid = [_throughput(f"setup3-{s}", 50, t / 2) for s in (25, 50, 100, 200)]
    return {
        "benchmark": "engine",
        "setup1": headline,
        "scaling_agents": sorted(headline + scaling_agents, key=lambda r: r["agents"]),
        "scaling_grid": scaling_grid,
    }


def format_engine_bench(result: dict) -> str:
    lines = ["In-process engine, one core, c-marking, whole runs to completion", ""]
    lines.append(f"{'scenario':<14}{'agents':>7}{'runs':>6}{'agent-steps':>14}{'steps/s':>14}")
    for row in result["scaling_agents"] + result["scaling_grid"]:
        lines.append(
            f"{row['scenario']:<14}{row['agents']:>7}{row['runs']:>6}{row['agent_steps']:>14,}"
            f"{row['agent_steps_per_second']:>14,}"
        )
    head = ", ".join(f"{r['agents']} agents: {r['agent_steps_per_second']:,}/s" for r in result["setup1"])
    lines += ["", f"setup1 headline: {head}"]
    return "\n".join(lines)
