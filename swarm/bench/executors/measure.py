"""`swarm bench executors`: what running an experiment through Ray costs on one machine.

`swarm experiment carrot` (cases 1 and 2 of the DFT paper's baseline, 12 runs per rep) runs as a user
runs it, a command of its own, with `--jobs 2`, three ways: through the local pool; with `--executor
ray`, which starts Ray on this machine and stops it within the command; and with `--executor ray
--address`, on a cluster of this machine's cores that is already running (`ray start --head`, started
10 s before the command and stopped after it, untimed: a study's commands share one).  Rounds alternate
the order (the machine's speed drifts), after an untimed run that compiles the kernels; each time is
the whole command's wall time.  Every run's rows, and the summary, must be the same every way
(wall-clock columns aside)."""

from __future__ import annotations

import contextlib
import csv
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from statistics import median

from swarm.experiments.ray_head import RayHead

EXPERIMENT = "carrot"
JOBS = 2
WALL_CLOCK = {"wall_s", "wall_seconds"}  # seconds a run took: no two runs share them
EXECUTORS = ("local", "ray", "ray-cluster")
HEAD_SETTLE = 10.0  # s a fresh head is left before a command uses it, as a study's long-running one would be


def command(executor: str, reps: int, out: Path, address: str | None = None) -> list[str]:
    where = ["--executor", "ray", "--address", address] if address else ["--executor", executor]
    return [sys.executable, "-m", "swarm", "experiment", EXPERIMENT, "--reps", str(reps), "--jobs", str(JOBS),
            *where, "--out", str(out)]  # fmt: skip


@contextlib.contextmanager
def _place(executor: str, here: str) -> Iterator[str | None]:
    """Where the command sends its runs: a running cluster's address, or None (it starts its own)."""
    if executor != "ray-cluster":
        yield None
        return
    with RayHead(JOBS, here, own=False) as head:  # Ray's defaults, as a user starts one
        address = head.address()
        time.sleep(HEAD_SETTLE)  # the head starts its workers as it comes up: not the command's cost
        yield address


def bench_executors(quick: bool = False) -> dict:
    import swarm

    reps, rounds = (1, 1) if quick else (24, 2)
    # the commands import this swarm (a checkout's, too), as this process does
    here = str(Path(swarm.__file__).resolve().parents[1])
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [here, os.environ.get("PYTHONPATH")])))
    seconds: dict[str, list[float]] = {name: [] for name in EXECUTORS}
    same = True
    with tempfile.TemporaryDirectory(prefix="swarm-executors-") as folder:
        # a first run, untimed, compiles (or loads) the kernels, which no timed command should pay
        subprocess.run(command("local", 1, Path(folder) / "warm"), env=env, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, check=True)  # fmt: skip
        for r in range(rounds):
            for name in EXECUTORS if r % 2 == 0 else EXECUTORS[::-1]:
                out = Path(folder) / f"{name}-{r}"
                with _place(name, here) as address:
                    cmd = command(name, reps, out, address)
                    started = time.perf_counter()
                    done = subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
                    seconds[name].append(time.perf_counter() - started)
                if done.returncode != 0:
                    raise RuntimeError(f"{' '.join(cmd[2:])} failed: {done.stderr.strip()}")
            first = Path(folder) / "local-0"
            same &= all(_rows(first / f) == _rows(Path(folder) / f"{n}-{r}" / f)
                        for n in EXECUTORS for f in ("runs.csv", "summary.csv"))  # fmt: skip
    medians = {name: median(times) for name, times in seconds.items()}
    return {"experiment": EXPERIMENT, "reps": reps, "jobs": JOBS, "rounds": rounds, "cpus": os.cpu_count(),
            "seconds": seconds, "medians": medians, "identical": same,
            "slowdown": {name: medians[name] / medians["local"] - 1.0 for name in EXECUTORS[1:]}}  # fmt: skip


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return [{k: v for k, v in row.items() if k not in WALL_CLOCK} for row in csv.DictReader(f)]


def format_executors_bench(r: dict) -> str:
    lines = [f"swarm experiment {r['experiment']} --reps {r['reps']} --jobs {r['jobs']} on {r['cpus']} cores, "
             f"{r['rounds']} rounds alternated (whole commands):"]  # fmt: skip
    how = {"local": "--executor local", "ray": "--executor ray (Ray started and stopped by the command)",
           "ray-cluster": "--executor ray --address (a running cluster)"}  # fmt: skip
    for name in EXECUTORS:
        times = "  ".join(f"{s:6.1f} s" for s in r["seconds"][name])
        lines.append(f"  {times}   median {r['medians'][name]:6.1f} s   {how[name]}")
    for name in EXECUTORS[1:]:
        lines.append(f"  {how[name]}: {100 * r['slowdown'][name]:+.1f}% wall time against the local pool "
                     "(target: at most +15%)")  # fmt: skip
    lines.append(f"  runs.csv and summary.csv {'identical' if r['identical'] else 'DIFFER'} every way")
    return "\n".join(lines)
