"""`swarm sweep FILE.toml`: a parameter sweep over scenarios, a grid of their parameters and seeds (swarm.sweeps)."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from swarm.core.tables import positive
from swarm.experiments.executors import add_executor_options

EPILOG = """\
a sweep file:
  scenarios = ["zmaze", "my_floor.toml"]   # presets, bundled names or files (relative to the sweep file)
  controller = "wander"                    # optional: every group's controller (a name or module:Class)
  agents = [1, 4]                          # optional: a list is an axis, one value a fixed setting
  seeds = { first = 1, count = 5 }         # or [1, 2, 3] (default [0])
  max_ticks = 500                          # arena: max_ticks, noise, on_controller_error;
                                           # grid: max_iterations, until, physics, body_diameter
  metrics = ["reached", "collisions", "distance"]   # summary keys (a robots' key: their mean),
                                                    # or module:function(summary) -> float
  [grid]                                   # dotted keys of the scenario's tables, each a list of values
  "wander.speed" = [0.4, 0.6, 0.8]
  "wander.turn_chance" = [0.02, 0.05]

writes runs.csv (one row a run, kept as runs end: rerunning resumes), runs.parquet,
summary.csv (n, mean, std, 95% t interval per condition) and METRIC.png per metric."""


def add_sweep_parser(sub) -> None:
    p = sub.add_parser(
        "sweep",
        help="run scenarios over a grid of parameters and seeds; runs.csv, summary.csv, plots",
        description="Run every scenario of a sweep file with every combination of its grid's values and "
        "settings, on every seed, each run in process as `swarm run` would, in a pool of worker processes. "
        "Every value is checked by the scenario parser before any run starts; runs already in runs.csv are "
        "not run again.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=EPILOG,
    )
    p.add_argument("file", type=Path, metavar="FILE.toml", help="the sweep file")
    p.add_argument("--jobs", type=positive, metavar="N", help="workers (default: every core, or the Ray cluster's)")
    add_executor_options(p)
    p.add_argument("--out", type=Path, metavar="DIR", help="output folder (default results/sweeps/<file stem>)")
    p.add_argument("--fresh", action="store_true", help="start over: forget the runs already in runs.csv")
    p.add_argument("--json", action="store_true", help="print one JSON object: runs, folder, files")
    p.set_defaults(handler=cmd_sweep)


def cmd_sweep(args) -> int:
    from swarm.sweeps import run_sweep

    start = time.perf_counter()
    result = run_sweep(args.file, jobs=args.jobs, out=args.out, fresh=args.fresh,
                       progress=not args.json and sys.stderr.isatty())  # fmt: skip
    wall = time.perf_counter() - start
    if args.json:
        print(json.dumps({k: v for k, v in result.items() if k != "rows"} | {"runs": len(result["rows"]),
                         "wall_s": round(wall, 3)}))  # fmt: skip
        return 0
    print(f"swarm sweep {args.file}: {len(result['rows'])} runs ({result['ran']} run now, {result['reused']} "
          f"already in runs.csv) in {wall:.1f} s")  # fmt: skip
    parquet = f" (no runs.parquet: {result['no_parquet']})" if result["no_parquet"] else ""
    print(f"wrote {', '.join(result['files'])}{parquet}")
    return 0
