"""What a soak leaves in its --out folder: the memory samples as CSV and, where matplotlib is installed,
their plot."""

from __future__ import annotations

import contextlib
import csv
from pathlib import Path


def write_files(result: dict, out: Path) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    written = [_write_csv(result["samples"], out / "soak.csv")]
    with contextlib.suppress(ImportError):  # matplotlib is an optional dependency: the CSV says the same
        written.append(_plot(result, out / "soak.png"))
    return written


def _write_csv(samples: dict[str, list[tuple[float, float]]], path: Path) -> Path:
    """seconds since every agent process joined, process, resident kB."""
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["seconds", "process", "rss_kb"])
        for role, rows in samples.items():
            w.writerows((round(t, 1), role, kb) for t, kb in rows)
    return path


def _plot(result: dict, path: Path) -> Path:
    """Resident memory over the run, one line per process, the measured span shaded."""
    from swarm.core.plots import pyplot, save_figure

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 4))
    for role, rows in result["samples"].items():
        if rows:
            ax.plot([t / 60 for t, _ in rows], [kb / 1024 for _, kb in rows], label=role)
    start, end = result["span_s"]
    ax.axvspan(start / 60, end / 60, alpha=0.1, label="growth measured")
    ax.set_xlabel("minutes since every agent process joined")
    ax.set_ylabel("resident memory (MB)")
    ax.set_title(f"soak, {result['kind']}: a SIGKILL every {result['kill_every']:g} s")
    ax.legend()
    save_figure(fig, path)
    return path
