"""`swarm bench executors`: what running an experiment through Ray costs on one machine.

`swarm experiment carrot` (cases 1 and 2 of the DFT paper's baseline, 12 runs per rep) runs as a user
runs it, a command of its own, with `--jobs 2`: through the local pool, and with `--executor ray`, which
starts Ray on this machine and stops it within the command.  Rounds alternate the two (the machine's
speed drifts), after an untimed run that compiles the kernels; each time is the whole command's wall
time.  Every run's rows, and the summary, must be
the same both ways (wall-clock columns aside)."""

from __future__ import annotations

import csv
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from statistics import median

EXPERIMENT = "carrot"
JOBS = 2
WALL_CLOCK = {"wall_s", "wall_seconds"}  # seconds a run took: no two runs share them
EXECUTORS = ("local", "ray")


def command(executor: str, reps: int, out: Path) -> list[str]:
    return [sys.executable, "-m", "swarm", "experiment", EXPERIMENT, "--reps", str(reps), "--jobs", str(JOBS),
            "--executor", executor, "--out", str(out)]  # fmt: skip


def bench_executors(quick: bool = False) -> dict:
    import swarm

    reps, rounds = (1, 1) if quick else (24, 2)
    # the commands import this swarm (a checkout's, too), as this process does
    here = str(Path(swarm.__file__).resolve().parents[1])
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [here, os.environ.get("PYTHONPATH")])))
    seconds: dict[str, list[float]] = {name: [] for name in EXECUTORS}
    same = True
    with tempfile.TemporaryDirectory(prefix="swarm-executors-") as folder:
        # a first run, untimed, compiles (or loads) the kernels, which neither timed command should pay
        subprocess.run(command("local", 1, Path(folder) / "warm"), env=env, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, check=True)  # fmt: skip
        for r in range(rounds):
            for name in EXECUTORS if r % 2 == 0 else EXECUTORS[::-1]:
                out = Path(folder) / f"{name}-{r}"
                started = time.perf_counter()
                done = subprocess.run(command(name, reps, out), env=env, stdout=subprocess.DEVNULL,
                                      stderr=subprocess.PIPE, text=True)  # fmt: skip
                seconds[name].append(time.perf_counter() - started)
                if done.returncode != 0:
                    raise RuntimeError(f"{' '.join(command(name, reps, out)[2:])} failed: {done.stderr.strip()}")
            first = Path(folder) / "local-0"
            same &= all(_rows(first / f) == _rows(Path(folder) / f"{n}-{r}" / f)
                        for n in EXECUTORS for f in ("runs.csv", "summary.csv"))  # fmt: skip
    local, ray = median(seconds["local"]), median(seconds["ray"])
    return {"experiment": EXPERIMENT, "reps": reps, "jobs": JOBS, "rounds": rounds, "cpus": os.cpu_count(),
            "local_s": seconds["local"], "ray_s": seconds["ray"], "local_median_s": local, "ray_median_s": ray,
            "slowdown": ray / local - 1.0, "identical": same}  # fmt: skip


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return [{k: v for k, v in row.items() if k not in WALL_CLOCK} for row in csv.DictReader(f)]


def format_executors_bench(r: dict) -> str:
    lines = [f"swarm experiment {r['experiment']} --reps {r['reps']} --jobs {r['jobs']} on {r['cpus']} cores, "
             f"{r['rounds']} rounds alternated (whole commands, Ray's start and stop included):"]  # fmt: skip
    for name in EXECUTORS:
        times = "  ".join(f"{s:6.1f} s" for s in r[f"{name}_s"])
        lines.append(f"  --executor {name:5}  {times}   median {r[f'{name}_median_s']:6.1f} s")
    lines.append(f"  ray: {100 * r['slowdown']:+.1f}% wall time (target: at most +15%); runs.csv and summary.csv "
                 f"{'identical' if r['identical'] else 'DIFFER'}")  # fmt: skip
    return "\n".join(lines)
