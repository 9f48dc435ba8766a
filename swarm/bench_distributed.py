"""`swarm bench distributed`: the lock-step runtime against the messaging floor.

For each swarm size, measured in the same command on the same machine: the
bare floor (`swarm.floor`, the method of shared/probes/lockstep_floor.py:
processes that answer each observation and do nothing else), our runtime
with a null controller and no world work, and the real run (world rules,
c-marking controllers); the real run's ticks per second as a share of the
floor.  Also 1000 agents packed 100 per process against the floor of 10
processes, tick latency, payload bytes per agent-step, agent process memory,
and the slowdown against the in-process engine on the same scenario.
"""

from __future__ import annotations

import time

from swarm.engine import Engine
from swarm.floor import floor
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


def bench_distributed(sizes=SIZES, ticks: int = 600, packed: int = 1000, port: int = 7600) -> dict:
    """600 ticks a row: at 100 processes some 6 s each for the floor and the run,
    long enough that a few slow ticks (this machine's speed drifts) do not
    decide the share; the processes' start is not timed."""
    rows = []
    for i, n in enumerate(sizes):
        bare = floor(n, ticks, f"tcp/127.0.0.1:{port + 3 * i + 2}")
        null = _one(n, ticks, 1, True, port + 3 * i + 1)
        real = _one(n, ticks, 1, False, port + 3 * i)
        engine = _engine_tps(n, 2000)
        real["floor_ticks_per_second"] = bare["ticks_per_second"]
        real["null_ticks_per_second"] = null["ticks_per_second"]
        real["share_of_floor"] = round(real["ticks_per_second"] / bare["ticks_per_second"], 3)
        real["engine_ticks_per_second"] = round(engine)
        real["slowdown_vs_engine"] = round(engine / real["ticks_per_second"], 1)
        rows.append(real)
    result = {"benchmark": "distributed", "scenario": "setup1", "mode": "lockstep", "runs": rows}
    if packed:
        per = 100
        # Five times the ticks: at some 300 ticks/s, 600 would be 2 s, much of it the first ticks' warm-up.
        result["packed"] = row = _one(packed, 5 * ticks, per, False, port + 99)
        row["floor_ticks_per_second"] = floor(packed // per, ticks, f"tcp/127.0.0.1:{port + 98}")["ticks_per_second"]
        row["share_of_floor"] = round(row["ticks_per_second"] / row["floor_ticks_per_second"], 3)
    return result


def format_distributed_bench(result: dict) -> str:
    lines = ["Distributed lock-step runtime, setup1, one process per agent. floor: the bare exchange",
             "(swarm.floor, the method of shared/probes/lockstep_floor.py); null: our runtime, no controller",
             "and no world work; ticks/s: the real run; share: ticks/s over floor", "",
             f"{'agents':>7}{'floor':>8}{'null':>8}{'ticks/s':>9}{'share':>7}{'p50 ms':>8}{'p99 ms':>8}"
             f"{'B/step':>8}{'RSS MB':>8}{'engine x':>9}"]  # fmt: skip
    for r in result["runs"]:
        lines.append(f"{r['agents']:>7}{r['floor_ticks_per_second']:>8}{r['null_ticks_per_second']:>8}"
                     f"{r['ticks_per_second']:>9}{r['share_of_floor']:>7}{r['tick_ms_p50']:>8}{r['tick_ms_p99']:>8}"
                     f"{r['bytes_per_agent_step']:>8}{r['agent_process_rss_mb'] or '-':>8}"
                     f"{r['slowdown_vs_engine']:>9}")  # fmt: skip
    if "packed" in result:
        p = result["packed"]
        lines += ["", f"{p['agents']} agents packed {p['per_process']} per process: {p['ticks_per_second']} ticks/s "
                      f"({p['share_of_floor']} of the floor of {p['agents'] // p['per_process']} processes, "
                      f"{p['floor_ticks_per_second']}), {p['agent_steps_per_second']} agent-steps/s, "
                      f"p99 {p['tick_ms_p99']} ms, RSS {p['agent_process_rss_mb']} MB per process"]  # fmt: skip
    return "\n".join(lines)
