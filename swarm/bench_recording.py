"""`swarm bench recording`: what recording costs, in both runtimes.

In-process (`swarm run --record`): setup 1 to completion over several seeds,
ticks/s without and with the recording, and the file's bytes per tick.
Distributed (`swarm up`, lock-step, where recording is on by default): one run
with and one without, same seed (the runs are equal tick for tick).
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from swarm.engine import Engine
from swarm.launcher import swarm_up
from swarm.recording import Recorder, run_meta
from swarm.scenario import load_scenario
from world_server.server import new_run_id


def _warm_up(tmp: Path) -> None:
    """Compile (or load) both engine loops and import rerun before timing anything."""
    scenario = load_scenario("setup2").with_overrides(agents=2, seed=0)
    Engine(scenario).step(10)
    engine = Engine(scenario)
    recorder = Recorder(tmp / "warm.rrd", engine.world, run_meta(scenario, engine.world, "warm", "foraged", "warm"))
    engine.run(max_iterations=10, recorder=recorder)
    recorder.close()


def _in_process(agents: int, seeds: range, tmp: Path) -> dict:
    ticks = plain = recorded = size = 0.0
    for seed in seeds:
        scenario = load_scenario("setup1").with_overrides(agents=agents, seed=seed)
        engine = Engine(scenario)
        started = time.perf_counter()
        ticks += engine.run().iterations
        plain += time.perf_counter() - started
        engine = Engine(scenario)
        path = tmp / f"inproc-{agents}-{seed}.rrd"
        started = time.perf_counter()
        recorder = Recorder(path, engine.world, run_meta(scenario, engine.world, path.stem, "foraged", "in-process"))
        recorder.close(engine.run(recorder=recorder).summary)
        recorded += time.perf_counter() - started
        size += path.stat().st_size
    return {"runtime": "in-process", "agents": agents, "runs": len(seeds), "ticks": int(ticks),
            "ticks_per_second": round(ticks / plain), "recorded_ticks_per_second": round(ticks / recorded),
            "cost": round(1 - plain / recorded, 3), "bytes_per_tick": round(size / ticks),
            "mb_per_run": round(size / len(seeds) / 1e6, 2)}  # fmt: skip


def _distributed(agents: int, per_process: int, tmp: Path, port: int) -> dict:
    rates, size, ticks = {}, 0, 0
    for record in (False, True):
        run_id = f"benchrec{new_run_id()}"
        path = tmp / f"{run_id}.rrd"
        s = swarm_up("setup1", agents, "cmarking", 1, run_id, f"tcp/127.0.0.1:{port + record}", deadline=10.0,
                     progress=False, per_process=per_process, record=str(path) if record else None)  # fmt: skip
        rates[record] = s["ticks_per_second"]
        if record:
            size, ticks = path.stat().st_size, s["iterations"]
    return {"runtime": "distributed", "agents": agents, "per_process": per_process, "ticks": ticks,
            "ticks_per_second": rates[False], "recorded_ticks_per_second": rates[True],
            "cost": round(1 - rates[True] / rates[False], 3), "bytes_per_tick": round(size / max(ticks, 1)),
            "mb_per_run": round(size / 1e6, 2)}  # fmt: skip


def bench_recording(quick: bool = False, port: int = 7650) -> dict:
    seeds = range(1, 3 if quick else 6)
    with tempfile.TemporaryDirectory(prefix="swarm-bench-rec-") as tmp:
        _warm_up(Path(tmp))
        rows = [_in_process(n, seeds, Path(tmp)) for n in (20, 160)]
        rows += [_distributed(20, 1, Path(tmp), port), _distributed(160, 10, Path(tmp), port + 2)]
    return {"benchmark": "recording", "scenario": "setup1", "runs": rows}


def format_recording_bench(result: dict) -> str:
    header = f"{'runtime':>12}{'agents':>7}{'ticks/s':>10}{'recorded':>10}{'cost':>7}{'B/tick':>8}{'MB/run':>8}"
    lines = ["Recording cost, setup1 to completion (cost = share of ticks/s lost to recording)", "", header]
    for r in result["runs"]:
        lines.append(f"{r['runtime']:>12}{r['agents']:>7}{r['ticks_per_second']:>10}"
                     f"{r['recorded_ticks_per_second']:>10}{r['cost']:>7.0%}{r['bytes_per_tick']:>8}"
                     f"{r['mb_per_run']:>8}")  # fmt: skip
    return "\n".join(lines)
