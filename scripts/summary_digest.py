"""One digest of what swarm prints and writes, to prove a refactoring changed nothing for a user.

Runs a fixed set of short runs (both runtimes, grid and arena, all four papers' controllers), a
recording read back, and short experiments of every paper through the `swarm` command, the way a
user would, then hashes their summaries, CSVs and tables.  Wall-clock fields (seconds, rates) and
the temporary paths are left out: everything else must be equal, bit for bit.

    python scripts/summary_digest.py                  # prints one digest per job, then the total
    python scripts/summary_digest.py --keep DIR       # also keeps the normalized outputs, to diff two runs
    python scripts/summary_digest.py --only run-      # the jobs whose name starts with run-
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import io
import json
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

# Keys (JSON) and columns (CSV) that measure the machine, not the model.
VOLATILE = re.compile(r"(^|_)(wall|per_second|elapsed|run_id|compile|rss|tick_ms)($|_)|^seconds$")

SWARM = [sys.executable, "-m", "swarm"]
OUTPUTS = "runs.csv summary.csv table.md"

# name -> (arguments of `swarm`, files of its output folder to hash). {out} is a fresh folder per job;
# "@report F" hashes `swarm report F --json`, the recording read back.
JOBS: dict[str, tuple[str, str]] = {
    "run-grid-cmarking": ("run setup1 --agents 5 --seed 1 --max-iterations 300 --json", ""),
    "run-grid-ant": ("run setup1 --controller ant --agents 5 --seed 2 --max-iterations 300 --json", ""),
    "run-grid-marking-physical": (
        "run maze --controller marking --physics physical --agents 4 --seed 1 --max-iterations 150 --json",
        "",
    ),
    "run-arena-carrot": ("run zmaze --seed 1 --max-ticks 300 --json", ""),
    "run-arena-dft": ("run zmaze --controller dft --seed 1 --max-ticks 300 --json", ""),
    "run-arena-fingerprint": ("run office --controller fingerprint --seed 1 --max-ticks 400 --json", ""),
    "run-arena-bg": ("run bg-exp1 --seed 1 --max-ticks 600 --json", ""),
    "record-arena": (
        "run large-maze --agents 3 --seed 2 --max-ticks 200 --record {out}/arena.rrd --json",
        "@report {out}/arena.rrd",
    ),
    "record-grid": (
        "run setup1 --agents 4 --seed 3 --max-iterations 120 --record {out}/grid.rrd --json",
        "@report {out}/grid.rrd",
    ),
    "up-grid": ("up setup1 --agents 4 --seed 1 --max-iterations 100 --no-record --json", ""),
    "up-arena-dft": ("up zmaze --controller dft --seed 1 --max-ticks 120 --no-record --json", ""),
    "up-arena-bg-colony": ("up bg-colony --seed 1 --max-ticks 120 --no-record --json", ""),
    "up-record-grid": (
        "up setup1 --agents 3 --seed 2 --max-iterations 60 --record {out}/up-grid.rrd --json",
        "@report {out}/up-grid.rrd",
    ),
    "up-record-arena": (
        "up zmaze --controller carrot --seed 2 --max-ticks 80 --record {out}/up-arena.rrd --json",
        "@report {out}/up-arena.rrd",
    ),
    "exp-table2": ("experiment table2 --reps 3 --jobs 2 --out {out}", OUTPUTS),
    "exp-carrot": ("experiment carrot --scenario zmaze --reps 2 --jobs 2 --out {out}", OUTPUTS),
    "exp-dft-case1": ("experiment dft-case1 --reps 1 --noise high --jobs 2 --out {out}", OUTPUTS),
    "exp-fingerprint-localize": ("experiment fingerprint-localize --reps 1 --jobs 2 --out {out}", OUTPUTS),
    "exp-bg-tmaze": (
        "experiment bg-tmaze --reps 2 --maps 2 --ratios 1 --jobs 2 --out {out}",
        OUTPUTS + " maps.json",
    ),
}


def normalize_json(value):
    """The value with every volatile key dropped (recursively) and floats kept as JSON writes them."""
    if isinstance(value, dict):
        return {k: normalize_json(v) for k, v in sorted(value.items()) if not VOLATILE.search(str(k))}
    if isinstance(value, list):
        return [normalize_json(v) for v in value]
    return value


def normalize_text(name: str, text: str, out: Path) -> str:
    text = text.replace(str(out), "{out}")
    if name.endswith(".csv"):
        rows = list(csv.reader(io.StringIO(text)))
        if not rows:
            return text
        keep = [i for i, col in enumerate(rows[0]) if not VOLATILE.search(col)]
        return "\n".join(",".join(row[i] for i in keep if i < len(row)) for row in rows)
    if name.endswith(".json"):
        return json.dumps(normalize_json(json.loads(text)), sort_keys=True)
    # Markdown tables: drop lines that report the machine's speed.
    return "\n".join(line for line in text.splitlines() if not re.search(r"wall|/s\b|per second|seconds of CPU", line))


def run_job(name: str, command: str, files: str, out: Path) -> str:
    argv = command.replace("{out}", str(out)).split()
    done = subprocess.run([*SWARM, *argv], capture_output=True, text=True, timeout=1800)
    # 1 is a run that ended unfinished (at its tick cap): its summary is as much part of the digest.
    if done.returncode not in (0, 1) or (done.returncode == 1 and "--json" not in argv):
        raise SystemExit(f"{name}: swarm {' '.join(argv)} exited {done.returncode}:\n{done.stderr[-2000:]}")
    parts = [("exit", str(done.returncode))]
    if "--json" in argv:
        summary = json.dumps(normalize_json(json.loads(done.stdout)), sort_keys=True)
        parts.append(("stdout", summary.replace(str(out), "{out}")))
    if files.startswith("@report "):
        rrd = files.split(" ", 1)[1].replace("{out}", str(out))
        report = [*SWARM, "report", rrd, "--json", "--out", str(out / "report")]
        rep = subprocess.run(report, capture_output=True, text=True, timeout=600)
        if rep.returncode != 0:
            raise SystemExit(f"{name}: swarm report exited {rep.returncode}:\n{rep.stderr[-2000:]}")
        parts.append(("report", json.dumps(normalize_json(json.loads(rep.stdout)), sort_keys=True)))
    else:
        for f in files.split():
            parts.append((f, normalize_text(f, (out / f).read_text(), out)))
    return "\n".join(f"== {label}\n{text}" for label, text in parts) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--keep", type=Path, help="write each job's normalized output to DIR/<job>.txt")
    parser.add_argument("--only", default="", help="run only the jobs whose name starts with this")
    opts = parser.parse_args()
    total = hashlib.sha256()
    if opts.keep:
        opts.keep.mkdir(parents=True, exist_ok=True)
    for name, (command, files) in JOBS.items():
        if not name.startswith(opts.only):
            continue
        start = time.perf_counter()
        with tempfile.TemporaryDirectory(prefix="digest-") as tmp:
            text = run_job(name, command, files, Path(tmp))
        digest = hashlib.sha256(text.encode()).hexdigest()
        total.update(f"{name}:{digest}\n".encode())
        if opts.keep:
            (opts.keep / f"{name}.txt").write_text(text)
        print(f"{name:28s} {digest[:16]}  ({time.perf_counter() - start:.0f} s)", flush=True)
    print(f"{'total':28s} {total.hexdigest()[:16]}")


if __name__ == "__main__":
    main()
