"""One plot per metric of a sweep: its mean against the first axis that varies, one line per
combination of the other varying columns, error bars the 95% interval."""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from pathlib import Path

from swarm.core.plots import plot_writer
from swarm.sweeps.outputs import cell


def x_axis(summary: Sequence[dict], columns: Sequence[str]) -> tuple[str, list[str]]:
    """(the x column, the columns that tell lines apart): the first of `columns` whose value varies, and
    the others that vary (the scenario last); the scenario on x when nothing else varies."""
    varying = [c for c in columns if len({cell(r[c]) for r in summary}) > 1]
    x = varying[0] if varying else "scenario"
    return x, [c for c in varying if c != x]


def plot_metrics(summary: Sequence[dict], columns: Sequence[str], metrics: Sequence[str], out: Path) -> list[Path]:
    """metric.png for each metric into `out` (`columns`: the axes in order, then the scenario)."""
    plt, save, written = plot_writer(out)
    x, others = x_axis(summary, columns)
    numeric = all(isinstance(r[x], int | float) and not isinstance(r[x], bool) for r in summary)
    ticks = list(dict.fromkeys(cell(r[x]) for r in summary))
    lines: dict[str, list[dict]] = {}
    for r in summary:
        lines.setdefault(", ".join(f"{c}={cell(r[c])}" for c in others), []).append(r)
    for m in metrics:
        fig, ax = plt.subplots(figsize=(6.4, 4.2))
        for label, rows in lines.items():
            rows = sorted(rows, key=lambda r: r[x]) if numeric else rows
            xs = [r[x] if numeric else ticks.index(cell(r[x])) for r in rows]
            mean = [r[f"{m}_mean"] for r in rows]
            err = [[_gap(r[f"{m}_mean"], r[f"{m}_ci_low"]) for r in rows],
                   [_gap(r[f"{m}_ci_high"], r[f"{m}_mean"]) for r in rows]]  # fmt: skip
            ax.errorbar(xs, mean, yerr=err, marker="o", capsize=3, label=label or None)
        if not numeric:
            ax.set_xticks(range(len(ticks)), ticks, rotation=20 if len(ticks) > 3 else 0)
        ax.set_xlabel(x)
        ax.set_ylabel(f"{m} (mean, 95% CI)")
        if any(lines):
            ax.legend(fontsize="small")
        ax.grid(alpha=0.3)
        save(fig, f"{_file_name(m)}.png")
    return written


def _gap(a: float, b: float) -> float:
    """An error bar's length (none where the interval is unknown)."""
    return 0.0 if math.isnan(a) or math.isnan(b) else max(0.0, a - b)


def _file_name(metric: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", metric)
