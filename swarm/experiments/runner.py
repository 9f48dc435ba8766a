"""The one runner every paper's experiment goes through (Mesa's `batch_run` is the model).

An experiment is a function of one job (a condition and its replicate: seed, start/goal pair,
map) returning one row.  `batch_run` maps it over every job on the command's executor (worker
processes on this machine, or Ray actors: executors.py) with a progress bar, retries a failed job
once, and gives the rows back in the jobs' order, so a table never depends on which worker finished
first.  `write_outputs` writes what every experiment writes: its runs, its summary
rows, its markdown table (the paper's numbers beside ours) and the result `swarm experiment`
prints.
"""

from __future__ import annotations

import csv
import itertools
import sys
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any, TypeVar

from swarm.core import atomic
from swarm.core.errors import RunError
from swarm.experiments.executors import Executor, Failure, current, processes_for

__all__ = ["JobFailed", "Outputs", "batch_run", "cross", "processes_for", "write_csv"]
RETRIES = 1  # a job that fails is run once more: a worker lost to the machine is not the job's fault

Job = TypeVar("Job")


def cross(conditions: Iterable[Any], replicates: Iterable[Any]) -> list[tuple[Any, Any]]:
    """Every condition with every replicate, conditions outermost (conditions × seeds)."""
    return list(itertools.product(conditions, list(replicates)))


def batch_run(fn: Callable[[Job], dict], work: Sequence[Job], *, jobs: int | None = None, desc: str = "runs",
              progress: bool = True, warm_up: Callable[..., None] | None = None, warm_args: tuple = (),
              chunksize: int = 1, on_row: Callable[[int, dict], None] | None = None,
              executor: Executor | None = None) -> list[dict]:  # fmt: skip
    """`fn` over every job of `work` in `jobs` workers (default: one per CPU) of `executor` (default: the
    command's, swarm.experiments.executors.current(): processes on this machine unless --executor ray),
    rows in `work`'s order.

    `warm_up(*warm_args)` runs once here and once in each worker before any job, so compiling (or loading)
    kernels is never part of a run's wall time.  One local worker is this process itself.  A worker is
    handed `chunksize` jobs at once (many short runs).  A job that raises, or whose worker dies, is said
    on stderr and run once more; failing again, it stops the batch with JobFailed (a RunError: one line
    naming the job and its error).  `on_row(i, row)` is told of each row as it comes in (a sweep saves
    it at once, so a stopped one resumes).
    """
    from tqdm import tqdm

    if not work:
        return []
    executor = executor or current()
    rows: list[dict | None] = [None] * len(work)
    tries = [0] * len(work)
    todo = deque(range(len(work)))
    left = len(work)
    bar = tqdm(total=len(work), desc=desc, unit="run", disable=not progress)
    try:
        if warm_up is not None:
            warm_up(*warm_args)
        workers = executor.start(fn, executor.width(jobs, len(work)), warm_up, warm_args)
        try:
            while left:
                while todo and workers.free():
                    workers.submit([(i, work[i]) for i in _next_chunk(todo, chunksize, tries)])
                for i, outcome in workers.results():
                    if outcome is None:  # its worker died holding it: not tried
                        todo.appendleft(i)
                    elif isinstance(outcome, Failure):
                        tries[i] += 1
                        said = f"run {i + 1} of {len(work)} ({_brief(work[i])}) failed"
                        if tries[i] > RETRIES:
                            raise JobFailed(f"{said} twice: {outcome}")
                        tqdm.write(f"swarm: {said}: {outcome}; running it once more", file=sys.stderr)
                        todo.appendleft(i)
                    else:
                        rows[i] = outcome
                        left -= 1
                        if on_row is not None:
                            on_row(i, outcome)
                        bar.update()
        finally:
            workers.close()
    finally:
        bar.close()
    return rows  # type: ignore[return-value]


class JobFailed(RunError):
    """A job of batch_run failed once more than it forgives (RETRIES)."""


def _next_chunk(todo: deque[int], size: int, tries: list[int]) -> list[int]:
    """The next `size` jobs of `todo`; a job being retried goes alone, so no other job shares its fate."""
    chunk = [todo.popleft()]
    while len(chunk) < size and todo and not tries[chunk[0]] and not tries[todo[0]]:
        chunk.append(todo.popleft())
    return chunk


def _brief(job: Any) -> str:
    text = repr(job)
    return text if len(text) <= 120 else text[:119] + "…"


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
