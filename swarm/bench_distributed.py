"""`swarm bench distributed`: the lock-step runtime against its own floor.

For each swarm size: the real run (world rules, c-marking controllers) and the
floor of the design measured in the same command on the same machine: the
same processes with a null controller that only answers each observation and
a world that does no world work.  Also 1000 agents packed 100 per process,
tick latency, payload bytes per agent-step, agent process memory, and the
slowdown against the in-process engine on the same scenario.
"""

from __future__ import annotations

import time

from swarm.engine import Engine
from swarm.launcher import swarm_up
from swarm.scenario import load_scenario
from world_server.server import new_run_id

SIZES = (10, 50, 100, 200)


def _engine_tps(agents: int, ticks: int) -> float:
    engine = Engine(load_scenario("setup1").with_overrides(agents=agents, seed=1))
    started = time.perf_counter()
    engine.step(ticks)
    return engine.tick / (time.perf_counter() - started)


def _one(agents: int, ticks: int, per_process: int, null: bool, port: int) -> dict:
    run_id = f"bench{new_run_id()}"  # fresh: never resume an earlier bench's saved state
    s = swarm_up("setup1", agents, "cmarking", 1, run_id, f"tcp/127.0.0.1:{port}", "foraged", ticks,
                 deadline=10.0, progress=False, per_process=per_process, null=null)  # fmt: skip
    steps = max(1, s["agent_steps"])
    return {"agents": agents, "per_process": per_process, "null": null, "ticks": s["iterations"],
            "ticks_per_second": s["ticks_per_second"], "agent_steps_per_second": round(s["ticks_per_second"] * agents),
            "tick_ms_p50": s["tick_ms_p50"], "tick_ms_p99": s["tick_ms_p99"],
            "bytes_per_agent_step": round((s["payload_bytes_out"] + s["payload_bytes_in"]) / steps, 1),
            "missed_ticks": s["missed_ticks"], "agent_process_rss_mb": s.get("agent_process_rss_mb")}  # fmt: skip


def bench_distributed(sizes=SIZES, ticks: int = 200, packed: int = 1000, port: int = 7600) -> dict:
    rows = []
    for i, n in enumerate(sizes):
        real = _one(n, ticks, 1, False, port + 2 * i)
        floor = _one(n, ticks, 1, True, port + 2 * i + 1)
        engine = _engine_tps(n, 2000)
        real["floor_ticks_per_second"] = floor["ticks_per_second"]
        real["share_of_floor"] = round(real["ticks_per_second"] / floor["ticks_per_second"], 3)
        real["engine_ticks_per_second"] = round(engine)
        real["slowdown_vs_engine"] = round(engine / real["ticks_per_second"], 1)
        rows.append(real)
    result = {"benchmark": "distributed", "scenario": "setup1", "mode": "lockstep", "runs": rows}
    if packed:
        result["packed"] = _one(packed, ticks // 2, 100, False, port + 99)
    return result


def format_distributed_bench(result: dict) -> str:
    lines = ["Distributed lock-step runtime, setup1, one process per agent (floor: null controller, no world work)",
             "", f"{'agents':>7}{'ticks/s':>9}{'floor':>8}{'share':>7}{'p50 ms':>8}{'p99 ms':>8}"
             f"{'B/step':>8}{'RSS MB':>8}{'engine x':>9}"]  # fmt: skip
    for r in result["runs"]:
        lines.append(f"{r['agents']:>7}{r['ticks_per_second']:>9}{r['floor_ticks_per_second']:>8}"
                     f"{r['share_of_floor']:>7}{r['tick_ms_p50']:>8}{r['tick_ms_p99']:>8}"
                     f"{r['bytes_per_agent_step']:>8}{r['agent_process_rss_mb'] or '-':>8}"
                     f"{r['slowdown_vs_engine']:>9}")  # fmt: skip
    if "packed" in result:
        p = result["packed"]
        lines += ["", f"{p['agents']} agents packed {p['per_process']} per process: {p['ticks_per_second']} ticks/s, "
                      f"{p['agent_steps_per_second']} agent-steps/s, p99 {p['tick_ms_p99']} ms, "
                      f"RSS {p['agent_process_rss_mb']} MB per process"]  # fmt: skip
    return "\n".join(lines)
