"""`swarm bench soak`: a real-time `swarm up` (swarm.launcher, recording on, `--respawn` with a budget
larger than the kills) that runs `minutes`, while swarm.bench.soak.watch kills an agent process with SIGKILL
every `kill_every` seconds and samples resident memory.  Afterwards the recording is read back with
rerun's reader (swarm.review.report) and checked tick by tick, and the summary's loss counts against the
kills (swarm.bench.soak.checks)."""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from swarm.bench.soak import checks
from swarm.bench.soak.output import write_files
from swarm.bench.soak.watch import ROLES, Watch
from swarm.core.mesh import free_endpoint
from swarm.launcher import swarm_up
from swarm.review.report import read_recording
from world_server import kind_of
from world_server.server import new_run_id

RATE = 20.0  # ticks a second (`--mode realtime --rate`)
HERE = Path(__file__).parent
# kind -> its run (swarm_up's arguments); the length (ticks) is added from --minutes
RUNS = {
    "grid": {"scenario_ref": str(HERE / "grid.toml"), "agents": 8, "per_process": 2, "seed": 1},
    "arena": {"scenario_ref": str(HERE / "arena.toml"), "agents": 4, "per_process": 1, "seed": 1},
}
QUICK = {"minutes": 0.2, "kill_every": 4.0, "interval": 1.0}
INTERVAL = 5.0  # seconds between memory samples of a full soak
VERDICT = ("world", "launcher")  # the processes that live the whole run; agent processes are replaced
LAST_KILL_MARGIN = 15.0  # no kill in the run's last seconds: its replacement must join before the world ends


def _length(kind: str, seconds: float) -> dict:
    ticks = round(seconds * RATE)
    if kind == "grid":
        return {"max_iterations": ticks}
    return {"world_args": ["--max-ticks", str(ticks)]}


def soak(kind: str, minutes: float, kill_every: float, interval: float, folder: Path, progress: bool) -> dict:
    """One soak: the launcher's run in this thread (it installs a signal handler), the watch beside it."""
    run, duration = RUNS[kind], minutes * 60
    run_id, record = f"soak{new_run_id()}", folder / "soak.rrd"
    processes = run["agents"] // run["per_process"]
    kills = int(duration // kill_every) + 1
    kill_until = duration - min(LAST_KILL_MARGIN, duration / 3)
    watch = Watch(run_id, processes, duration, kill_every, kill_until, interval, progress)
    watch.start()
    try:
        summary = swarm_up(controller=None, run_id=run_id, listen=free_endpoint(), progress=False, mode="realtime",
                           rate=RATE, record=str(record), on_loss="respawn", max_respawns=kills, **run,
                           **_length(kind, duration))  # fmt: skip
    finally:
        watch.stop()
    played = summary.get("iterations", summary.get("ticks", 0))
    recorded = _recorded_ticks(record)
    window = max(duration / 60, interval)
    lasted = watch.samples["world"][-1][0] if watch.samples["world"] else 0.0  # the world's last sample
    memory = {role: {**checks.growth(watch.samples[role], lasted, window),
                     "verdict": role in VERDICT} for role in ROLES}  # fmt: skip
    return {"kind": kind, "minutes": minutes, "kill_every": kill_every, "rate": RATE, "agents": run["agents"],
            "per_process": run["per_process"], "seconds": round(lasted, 1),
            "played": played, "recorded": len(recorded), "missing_ticks": checks.missing_ticks(recorded, played),
            "losses": checks.losses(summary, len(watch.kill_times), run["per_process"]), "memory": memory,
            "span_s": [round(t) for t in checks.span(lasted)], "missed_ticks": summary.get("missed_ticks"),
            "clock_slips": summary.get("clock_slips"), "kill_times": watch.kill_times,
            "samples": watch.samples}  # fmt: skip


def _recorded_ticks(path: Path):
    """The ticks the recording holds, by its per-tick progress series (every tick logs one value)."""
    rec = read_recording(path)
    return rec.values(kind_of(rec.meta).progress[0])[0]


def run(quick: bool = False, minutes: float = 30.0, kill_every: float = 10.0, kind: str = "grid",
        out: str | None = None) -> dict:  # fmt: skip
    """`swarm bench soak` (--quick: a 12 s run, a kill every 4 s, memory sampled every second)."""
    if kind not in RUNS:
        raise ValueError(f"kind: expected one of {', '.join(RUNS)}, got {kind!r}")
    interval = INTERVAL
    if quick:
        minutes, kill_every, interval = QUICK["minutes"], QUICK["kill_every"], QUICK["interval"]
    with tempfile.TemporaryDirectory(prefix="swarm-soak-") as tmp:
        folder = Path(out) if out else Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        result = soak(kind, minutes, kill_every, interval, folder, sys.stderr.isatty())
    result["files"] = [str(p) for p in write_files(result, Path(out))] if out else []
    result["met"] = checks.met(result)
    return {"benchmark": "soak", "target_growth_pct": checks.TARGET_GROWTH, **result}
