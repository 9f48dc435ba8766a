"""The one runner every paper's experiment goes through (Mesa's `batch_run` is the model).

An experiment is a function of one job (a condition and its replicate: seed, start/goal pair,
map) returning one row.  `batch_run` maps it over every job in one process pool with a progress
bar and gives the rows back in the jobs' order, so a table never depends on which worker
finished first.  `write_outputs` writes what every experiment writes: its runs, its summary
rows, its markdown table (the paper's numbers beside ours) and the result `swarm experiment`
prints.
"""

from __future__ import annotations

import csv
import itertools
import multiprocessing as mp
import os
from collections.abc import Callable, Iterable, Sequence
from functools import partial
from pathlib import Path
from typing import Any, TypeVar

from swarm.core import atomic

Job = TypeVar("Job")


def cross(conditions: Iterable[Any], replicates: Iterable[Any]) -> list[tuple[Any, Any]]:
    """Every condition with every replicate, conditions outermost (conditions × seeds)."""
    return list(itertools.product(conditions, list(replicates)))


def processes_for(jobs: int | None, work: int) -> int:
    """Worker processes: `jobs` (default every core), never more than there is work."""
    return max(1, min(jobs or os.cpu_count() or 1, work))


def batch_run(fn: Callable[[Job], dict], work: Sequence[Job], *, jobs: int | None = None, desc: str = "runs",
              progress: bool = True, warm_up: Callable[..., None] | None = None, warm_args: tuple = (),
              chunksize: int = 1, on_row: Callable[[int, dict], None] | None = None) -> list[dict]:  # fmt: skip
    """`fn` over every job of `work` in `jobs` spawned processes (default: every core), rows in `work`'s order.

    `warm_up(*warm_args)` runs once here and once in each worker before any job, so compiling (or loading)
    kernels is never part of a run's wall time.  One process, or one job, runs here without a pool.
    `on_row(i, row)` is told of each row as it comes in (a sweep saves it at once, so a killed one resumes).
    """
    from tqdm import tqdm

    rows: list[dict | None] = [None] * len(work)
    processes = processes_for(jobs, len(work))
    bar = tqdm(total=len(work), desc=desc, unit="run", disable=not progress)
    try:
        if warm_up is not None:
            warm_up(*warm_args)
        if processes == 1:
            for i, job in enumerate(work):
                rows[i] = fn(job)
                if on_row is not None:
                    on_row(i, rows[i])
                bar.update()
        else:
            init = {"initializer": warm_up, "initargs": warm_args} if warm_up is not None else {}
            with mp.get_context("spawn").Pool(processes, **init) as pool:
                for i, row in pool.imap_unordered(partial(_numbered, fn), enumerate(work), chunksize=chunksize):
                    rows[i] = row
                    if on_row is not None:
                        on_row(i, row)
                    bar.update()
    finally:
        bar.close()
    return rows  # type: ignore[return-value]


def _numbered(fn: Callable[[Job], dict], numbered: tuple[int, Job]) -> tuple[int, dict]:
    i, job = numbered
    return i, fn(job)


def write_csv(path: Path, rows: Sequence[dict], fields: Sequence[str] | None = None) -> None:
    """`rows` as CSV, replaced whole (a kill leaves the old file or the new); the columns `fields`
    (others left out), by default every key in first-seen order."""
    fields = list(fields) if fields is not None else list(dict.fromkeys(k for row in rows for k in row))

    def write(f) -> None:
        writer = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)

    atomic.replace(path, write, text=True)


class Outputs:
    """What every experiment writes into its folder (by default results/<name>): runs.csv as soon as the
    runs are in (a report that fails later loses no run), then summary.csv and table.md."""

    def __init__(self, out: Path | str | None, name: str) -> None:
        self.name = name
        self.folder = Path(out) if out is not None else Path("results") / name
        self.folder.mkdir(parents=True, exist_ok=True)
        self.rows: Sequence[dict] = ()

    def __truediv__(self, file: str) -> Path:
        return self.folder / file

    def runs(self, rows: Sequence[dict], fields: Sequence[str] | None = None, file: str = "runs.csv") -> None:
        self.rows = rows
        write_csv(self.folder / file, rows, fields)

    def finish(self, summary: list[dict] | None, text: str, file: str = "table.md") -> dict:
        """summary.csv (where the experiment summarises its runs in rows) and the markdown `text`
        (table.md; a reproduction's is its report.md); the result `swarm experiment` prints."""
        if summary is not None:
            write_csv(self.folder / "summary.csv", summary)
        (self.folder / file).write_text(text)
        return {"name": self.name, "out": str(self.folder), "runs": len(self.rows), "summary": summary,
                "markdown": text}  # fmt: skip
