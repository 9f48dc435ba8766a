"""Parameter sweeps (Mesa's batch_run): every scenario × grid value × setting × seed of a sweep file,
each an in-process run of its world kind, through the experiments' runner (one process pool).

The modules: spec (the file, checked before any run), jobs (a run's scenario and its row),
outputs (runs.csv kept as runs end, runs.parquet, summary.csv), plots (one per metric).
`swarm sweep FILE.toml` is its command (swarm/cli_sweep.py); docs/commands.md describes the file.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from swarm.core.errors import ScenarioError
from swarm.sweeps.jobs import Job
from swarm.sweeps.outputs import RunsFile
from swarm.sweeps.spec import SweepSpec, read_spec

__all__ = ["SweepSpec", "read_spec", "run_sweep", "sweep"]


def sweep(path_or_dict: str | Path | Mapping[str, Any], jobs: int | None = None, out: str | Path | None = None,
          fresh: bool = False, progress: bool = True) -> list[dict]:  # fmt: skip
    """Run the sweep (a TOML file, or its tables as a dict) and write its outputs into `out` (default
    results/sweeps/<file stem>); its rows, one per run in job order, runs already in runs.csv included
    and not run again (`fresh`: start over).  ScenarioError, in one line, for anything it refuses."""
    return run_sweep(path_or_dict, jobs=jobs, out=out, fresh=fresh, progress=progress)["rows"]


def run_sweep(path_or_dict: str | Path | Mapping[str, Any], jobs: int | None = None, out: str | Path | None = None,
              fresh: bool = False, progress: bool = True) -> dict:  # fmt: skip
    """sweep(), and what it did: {"rows", "ran", "reused", "out", "files", "no_parquet"
    (why there is no runs.parquet, or None)}.  The folder also keeps
    sweep.json: the settings every run shares."""
    from swarm.experiments.runner import batch_run, cross
    from swarm.sweeps.jobs import check_metrics, run_job, warm_up

    spec = read_spec(path_or_dict)
    work = [Job(c, s, spec.metrics) for c, s in cross(spec.conditions(), spec.seeds)]
    folder = Path(out) if out is not None else Path("results") / "sweeps" / spec.name
    runs = RunsFile(folder / "runs.csv", ["scenario", *spec.axes, "seed"], [*spec.metrics, "wall_s"], fresh)
    todo = [job for job in work if runs.key(columns(job, spec)) not in runs.rows]
    fixed = _fixed(spec, folder, fresh)
    firsts = list({job.condition.scenario: job for job in reversed(todo)}.values())
    for job in firsts:  # an unknown metric is refused before any run (and the kernels are loaded here)
        check_metrics(job)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "sweep.json").write_text(json.dumps(fixed, indent=1) + "\n")
    runs.write(list(runs.rows.values()))  # a row a kill cut short is left out, so appending goes on cleanly
    if todo:
        batch_run(run_job, todo, jobs=jobs, desc=f"sweep {spec.name}", progress=progress, warm_up=warm_up,
                  warm_args=tuple(firsts), on_row=lambda i, row: runs.append(columns(todo[i], spec) | row))  # fmt: skip
    return _finish(spec, work, runs, folder) | {"ran": len(todo), "reused": len(work) - len(todo)}


def _fixed(spec: SweepSpec, folder: Path, fresh: bool) -> dict[str, Any]:
    """The settings every run shares (not columns of runs.csv), as sweep.json keeps them: runs made with
    others are not this sweep's, so resuming them is refused in one line."""
    fixed = {k: v[0] for k, v in spec.settings if k not in spec.axes}
    path = folder / "sweep.json"
    if path.exists() and (folder / "runs.csv").exists() and not fresh:
        before = json.loads(path.read_text())
        if before != fixed:
            raise ScenarioError(str(path), "settings", f"the runs in {folder} were made with {before}, this sweep "
                                f"sets {fixed}; rerun with --fresh, or give another --out")  # fmt: skip
    return fixed


def columns(job: Job, spec: SweepSpec) -> dict[str, Any]:
    """A run's key columns: its scenario, every axis's value, its seed."""
    values = dict(job.condition.grid) | dict(job.condition.settings)
    return {"scenario": job.condition.scenario, **{a: values[a] for a in spec.axes}, "seed": job.seed}


def _finish(spec: SweepSpec, work: list[Job], runs: RunsFile, folder: Path) -> dict:
    """runs.csv in job order (rows of other sweeps into the same folder kept after them), runs.parquet,
    summary.csv and the plots; the rows, typed."""
    from swarm.experiments.runner import write_csv
    from swarm.sweeps.outputs import summarise, write_parquet
    from swarm.sweeps.plots import plot_metrics

    keys = [runs.key(columns(job, spec)) for job in work]
    mine = set(keys)
    runs.write([runs.rows[k] for k in keys] + [r for k, r in runs.rows.items() if k not in mine])
    numbers = [{v: float(runs.rows[k][v]) for v in runs.values} for k in keys]
    rows = [columns(job, spec) | values for job, values in zip(work, numbers, strict=True)]
    no_parquet = write_parquet(rows, folder / "runs.parquet")
    summary = summarise(rows, ["scenario", *spec.axes], spec.metrics)
    write_csv(folder / "summary.csv", summary)
    plots = plot_metrics(summary, [*spec.axes, "scenario"], spec.metrics, folder)
    files = [folder / "runs.csv", *([] if no_parquet else [folder / "runs.parquet"]), folder / "summary.csv", *plots]
    return {"rows": rows, "out": str(folder), "files": [str(f) for f in files], "no_parquet": no_parquet}
