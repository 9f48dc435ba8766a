"""`swarm bench recording`: what recording costs, in both runtimes.

In-process (`swarm run --record`): setup 1 to completion over several seeds,
ticks/s without and with the recording, and the file's bytes per tick.
Distributed (`swarm up`, lock-step, where recording is on by default): runs
with and without, alternated, same seed (the runs are equal tick for tick).
Distributed arena: a user's kind of controller (payload.py), whose record()
each agent process sends the world every tick, at sizes from one scalar to a
128 x 128 image: what those messages cost a lock-step run.
"""

from __future__ import annotations

import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from swarm.engines.grid import Engine
from swarm.launcher import swarm_up
from swarm.recording.grid import Recorder, run_meta
from swarm.scenario import load_scenario
from world_server.server import new_run_id

QUICK_TICKS = 150  # a quick distributed run: enough ticks to time, few enough to take seconds
ARENA = Path(__file__).with_name("arena.toml")
ARENA_ROBOTS, ARENA_PER_PROCESS = 16, 4
ARENA_TICKS = 600  # a full bench's arena run: 10 s of its ticks/s timed, 60 images a robot
QUICK_ARENA_TICKS = 30
VIEWS = (0, 16, 64, 128)  # payload.py's record() images, cells a side


def _recorder(engine: Engine, path: Path, runtime: str = "in-process") -> Recorder:
    return Recorder(path, engine.world, run_meta(engine.scenario, engine.world, path.stem, "foraged", runtime))


def _warm_up(tmp: Path) -> None:
    """Compile (or load) both engine loops and import rerun before timing anything."""
    scenario = load_scenario("setup2").with_overrides(agents=2, seed=0)
    Engine(scenario).step(10)
    engine = Engine(scenario)
    recorder = _recorder(engine, tmp / "warm.rrd", "warm")
    engine.run(max_iterations=10, recorder=recorder)
    recorder.close()


def _in_process(agents: int, seeds: range, tmp: Path) -> dict:
    """Whole runs timed in three parts (opening the file, the run, closing it),
    so the table shows what a recording costs per run besides what it costs per tick."""
    ticks = plain = opening = running = closing = size = 0.0
    for seed in seeds:
        scenario = load_scenario("setup1").with_overrides(agents=agents, seed=seed)
        engine = Engine(scenario)
        started = time.perf_counter()
        ticks += engine.run().iterations
        plain += time.perf_counter() - started
        engine = Engine(scenario)
        path = tmp / f"inproc-{agents}-{seed}.rrd"
        started = time.perf_counter()
        recorder = _recorder(engine, path)
        opened = time.perf_counter()
        summary = engine.run(recorder=recorder).summary
        ran = time.perf_counter()
        recorder.close(summary)
        closed = time.perf_counter()
        opening, running, closing = opening + opened - started, running + ran - opened, closing + closed - ran
        size += path.stat().st_size
    recorded = opening + running + closing
    per_run = 1000 / len(seeds)
    return {"runtime": "in-process", "agents": agents, "runs": len(seeds), "ticks": int(ticks),
            "ticks_per_second": round(ticks / plain), "recorded_ticks_per_second": round(ticks / recorded),
            "cost": round(1 - plain / recorded, 3), "bytes_per_tick": round(size / ticks),
            "mb_per_run": round(size / len(seeds) / 1e6, 2), "plain_ms_per_run": round(plain * per_run, 1),
            "open_ms_per_run": round(opening * per_run, 1), "recorded_run_ms_per_run": round(running * per_run, 1),
            "close_ms_per_run": round(closing * per_run, 1),
            "drained_close_ms_per_run": _close_floor(agents, seeds, tmp)}  # fmt: skip


def _close_floor(agents: int, seeds: range, tmp: Path) -> float:
    """ms to close the file of a recorded run once every tick has long reached rerun
    (its data flushed, then 0.2 s idle): what no change on our side can save."""
    total = 0.0
    for seed in seeds:
        scenario = load_scenario("setup1").with_overrides(agents=agents, seed=seed)
        engine = Engine(scenario)
        path = tmp / f"floor-{agents}-{seed}.rrd"
        recorder = _recorder(engine, path)
        summary = engine.run(recorder=recorder).summary
        recorder.flush()
        recorder.rec.flush()
        time.sleep(0.2)
        started = time.perf_counter()
        recorder.close(summary)
        total += time.perf_counter() - started
    return round(total * 1000 / len(seeds), 1)


def _alternated(pairs: int, tmp: Path, port: int, up: Callable[[str, str, str | None], dict],
                ticks: int | None = None) -> dict:  # fmt: skip
    """`pairs` runs each way, alternated (plain, recorded, plain, ...): `up(run_id, listen, record)` runs one,
    same seed each time.  The median ticks/s of each way, since one lock-step run over zenoh moves by a
    few percent on its own, what recording costs, and the last recorded run's bytes a tick (over `ticks`,
    or the ticks it played) and in all."""
    rates: dict[bool, list[float]] = {False: [], True: []}
    size = played = 0
    for _ in range(pairs):
        for record in (False, True):
            run_id = f"benchrec{new_run_id()}"
            path = tmp / f"{run_id}.rrd"
            s = up(run_id, f"tcp/127.0.0.1:{port + record}", str(path) if record else None)
            rates[record].append(s["ticks_per_second"])
            if record:
                size, played = path.stat().st_size, s["iterations"]
    plain, recorded = statistics.median(rates[False]), statistics.median(rates[True])
    ticks = ticks or played
    return {"ticks": ticks, "ticks_per_second": round(plain, 2), "recorded_ticks_per_second": round(recorded, 2),
            "cost": round(1 - recorded / plain, 3), "bytes_per_tick": round(size / max(ticks, 1)),
            "mb_per_run": round(size / 1e6, 2)}  # fmt: skip


def _distributed(agents: int, per_process: int, tmp: Path, port: int, pairs: int, max_ticks: int) -> dict:
    """Setup 1 under `swarm up`, plain and recorded (_alternated)."""

    def up(run_id: str, listen: str, record: str | None) -> dict:
        return swarm_up("setup1", agents, "cmarking", 1, run_id, listen, deadline=10.0, max_iterations=max_ticks,
                        progress=False, per_process=per_process, record=record, on_loss="strict")  # fmt: skip

    return {
        "runtime": "distributed",
        "agents": agents,
        "per_process": per_process,
        "runs": pairs,
        **_alternated(pairs, tmp, port, up),
    }


def record_bytes(cells: int) -> float:
    """Bytes a robot's record() message carries a tick, on average: the scalars every tick, the image
    every ARRAYS_EVERY ticks (world_server/arena/face/wire.py)."""
    from world_server.arena.face.wire import ARRAYS_EVERY, record_message, record_values

    record = {"turning": 0} | ({"view": np.zeros((cells, cells), np.float32)} if cells else {})
    sizes = [len(record_message(tick, 0, record_values(record, tick)) or b"") for tick in range(ARRAYS_EVERY)]
    return sum(sizes) / ARRAYS_EVERY


def _arena_distributed(cells: int, tmp: Path, port: int, pairs: int, ticks: int,
                       per_process: int = ARENA_PER_PROCESS) -> dict:  # fmt: skip
    """ARENA_ROBOTS robots of payload.py's View<cells>, lock-step, plain and recorded (_alternated)."""

    def up(run_id: str, listen: str, record: str | None) -> dict:
        return swarm_up(str(ARENA), ARENA_ROBOTS, f"swarm.bench.recording.payload:View{cells}", 1, run_id, listen,
                        deadline=10.0, progress=False, per_process=per_process, record=record, on_loss="strict",
                        world_args=["--max-ticks", str(ticks)])  # fmt: skip

    return {
        "runtime": "arena",
        "agents": ARENA_ROBOTS,
        "per_process": per_process,
        "view": cells,
        "runs": pairs,
        "record_bytes": round(record_bytes(cells)),
        **_alternated(pairs, tmp, port, up, ticks),
    }


def bench_recording(quick: bool = False, port: int = 7650) -> dict:
    """`quick` checks every part in seconds rather than measuring: one seed in process, and
    distributed runs of few agent processes that stop at QUICK_TICKS."""
    seeds = range(1, 2 if quick else 6)
    pairs, max_ticks = (1, QUICK_TICKS) if quick else (3, 1_000_000)
    with tempfile.TemporaryDirectory(prefix="swarm-bench-rec-") as tmp:
        _warm_up(Path(tmp))
        rows = [_in_process(n, seeds, Path(tmp)) for n in (20, 160)]
        for i, (agents, per_process) in enumerate(((20, 10), (160, 40)) if quick else ((20, 1), (160, 10))):
            rows.append(_distributed(agents, per_process, Path(tmp), port + 2 * i, pairs, max_ticks))
        # --quick: the largest view, one agent process, a few ticks: the path runs, nothing is timed
        arena = {"ticks": QUICK_ARENA_TICKS, "per_process": ARENA_ROBOTS} if quick else {"ticks": ARENA_TICKS}
        for i, cells in enumerate(VIEWS[-1:] if quick else VIEWS):
            rows.append(_arena_distributed(cells, Path(tmp), port + 4 + 2 * i, pairs, **arena))
    return {"benchmark": "recording", "scenario": "setup1", "quick": quick, "runs": rows}


def format_recording_bench(result: dict) -> str:
    header = f"{'runtime':>12}{'agents':>7}{'ticks/s':>10}{'recorded':>10}{'cost':>7}{'B/tick':>8}{'MB/run':>8}"
    extent = f"--quick: distributed runs stop at {QUICK_TICKS} ticks" if result.get("quick") else "to completion"
    lines = [f"Recording cost, setup1 {extent} (cost = share of ticks/s lost to recording)", "", header]
    for r in (r for r in result["runs"] if r["runtime"] != "arena"):
        lines.append(f"{r['runtime']:>12}{r['agents']:>7}{r['ticks_per_second']:>10}"
                     f"{r['recorded_ticks_per_second']:>10}{r['cost']:>7.0%}{r['bytes_per_tick']:>8}"
                     f"{r['mb_per_run']:>8}")  # fmt: skip
    lines += ["", "In-process, per run (ms): the plain run, then the recorded one in its three parts", "",
              f"{'agents':>7}{'plain':>8}{'open':>8}{'run':>8}{'close':>8}{'20% budget':>12}"
              f"{'close, drained':>16}"]  # fmt: skip
    for r in result["runs"]:
        if r["runtime"] == "in-process":
            budget = r["plain_ms_per_run"] / 4  # recorded <= plain / 0.8, so extra <= plain / 4
            lines.append(f"{r['agents']:>7}{r['plain_ms_per_run']:>8}{r['open_ms_per_run']:>8}"
                         f"{r['recorded_run_ms_per_run']:>8}{r['close_ms_per_run']:>8}{budget:>12.1f}"
                         f"{r['drained_close_ms_per_run']:>16}")  # fmt: skip
    lines += [
        "",
        "close, drained: closing the file after all its data reached rerun and 0.2 s passed;",
        "rerun writes the file's footer (chunk index) and frees its buffers then, whatever we do before.",
    ]
    arena = [r for r in result["runs"] if r["runtime"] == "arena"]
    if arena:
        lines += ["", f"Distributed arena: {arena[0]['agents']} robots in processes of {arena[0]['per_process']}, "
                  f"{arena[0]['ticks']} ticks, lock-step; each robot's record() carries a view of cells x cells "
                  "float32 (sent as float64 every 10 ticks)", "",
                  f"{'view':>7}{'record B/robot-tick':>21}{'ticks/s':>10}{'recorded':>10}{'cost':>7}{'B/tick':>9}"
                  f"{'MB/run':>8}"]  # fmt: skip
        for r in arena:
            lines.append(f"{r['view']:>7}{r['record_bytes']:>21}{r['ticks_per_second']:>10}"
                         f"{r['recorded_ticks_per_second']:>10}{r['cost']:>7.0%}{r['bytes_per_tick']:>9}"
                         f"{r['mb_per_run']:>8}")  # fmt: skip
    return "\n".join(lines)
