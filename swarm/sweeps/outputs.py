"""What a sweep writes: runs.csv (one row a run, appended as each run ends, so a killed sweep resumes),
runs.parquet where pyarrow is installed, summary.csv (each condition's n, mean, std and 95% t interval
of each metric) and one plot per metric."""

from __future__ import annotations

import csv
import importlib.util
import io
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from swarm.core import atomic
from swarm.core.errors import ScenarioError

CONFIDENCE = 0.95


def cell(value: Any) -> str:
    """A value as runs.csv writes it (and reads it back, to know the runs it holds)."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list | dict):
        return json.dumps(value, sort_keys=True)
    return str(value)


class RunsFile:
    """runs.csv: the runs it holds by key (the key columns as text), and each new one appended at once."""

    def __init__(self, path: Path, keys: Sequence[str], values: Sequence[str], fresh: bool) -> None:
        self.path, self.keys = path, list(keys)
        self.values = list(values)  # the metrics, then wall_s: numbers
        self.fields = self.keys + self.values
        self.rows: dict[tuple[str, ...], dict[str, str]] = {}
        if path.exists() and not fresh:
            self._load()

    def _load(self) -> None:
        text = self.path.read_text()
        if not text.endswith("\n"):  # a row a kill cut short (perhaps inside its last number) is run again
            text = text[: text.rfind("\n") + 1]
        reader = csv.DictReader(io.StringIO(text, newline=""))
        if reader.fieldnames != self.fields:
            raise ScenarioError(str(self.path), "columns", "written by another sweep (its columns differ); "
                                "rerun with --fresh, or give another --out")  # fmt: skip
        for row in reader:
            if None in row.values() or None in row or not all(_is_number(row[k]) for k in self.values):
                continue
            self.rows[self.key(row)] = row

    def key(self, row: dict[str, Any]) -> tuple[str, ...]:
        return tuple(cell(row[k]) if not isinstance(row[k], str) else row[k] for k in self.keys)

    def append(self, row: dict[str, Any]) -> None:
        text = {k: cell(v) for k, v in row.items()}
        self.rows[self.key(text)] = text
        with open(self.path, "a", newline="") as f:
            csv.DictWriter(f, self.fields, extrasaction="ignore").writerow(text)

    def write(self, rows: Sequence[dict[str, str]]) -> None:
        """Replace the file with `rows` at once (a kill leaves the old file or the new, never half)."""

        def write(f) -> None:
            writer = csv.DictWriter(f, self.fields, extrasaction="ignore")
            writer.writeheader()
            writer.writerows(rows)

        atomic.replace(self.path, write, text=True)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def write_parquet(rows: Sequence[dict], path: Path) -> str | None:
    """runs.parquet (pandas and pyarrow); None when written, else why not, in a few words."""
    if importlib.util.find_spec("pyarrow") is None or importlib.util.find_spec("pandas") is None:
        return "pandas or pyarrow is not installed"
    import pandas as pd

    frame = pd.DataFrame([{k: cell(v) if isinstance(v, list | dict) else v for k, v in r.items()} for r in rows])
    try:
        frame.to_parquet(path, index=False)
    except (TypeError, ValueError) as exc:  # pyarrow's ArrowTypeError, ArrowInvalid: a column of mixed types
        path.unlink(missing_ok=True)
        return f"pyarrow refused the rows ({str(exc).splitlines()[0] if str(exc) else type(exc).__name__})"
    return None


def summarise(rows: Sequence[dict], conditions: Sequence[str], metrics: Sequence[str]) -> list[dict]:
    """One row per condition (the `conditions` columns' values, in first-seen order): n runs, and per
    metric its finite values' n, mean, std and 95% t interval of the mean (nan bounds below 2 values)."""
    groups: dict[tuple[str, ...], list[dict]] = {}
    for row in rows:
        groups.setdefault(tuple(cell(row[c]) for c in conditions), []).append(row)
    out = []
    for members in groups.values():
        summary = {c: members[0][c] for c in conditions} | {"n": len(members)}
        for m in metrics:
            summary |= _estimate(m, [float(r[m]) for r in members])
        out.append(summary)
    return out


def _estimate(name: str, values: list[float]) -> dict[str, float]:
    from scipy.stats import t

    x = np.asarray(values, float)
    x = x[np.isfinite(x)]
    mean = float(x.mean()) if len(x) else math.nan
    std = float(x.std(ddof=1)) if len(x) > 1 else math.nan
    if len(x) < 2:
        low = high = math.nan
    elif std == 0:
        low = high = mean
    else:
        low, high = (float(b) for b in t.interval(CONFIDENCE, len(x) - 1, loc=mean, scale=std / math.sqrt(len(x))))
    return {f"{name}_n": len(x), f"{name}_mean": mean, f"{name}_std": std, f"{name}_ci_low": low,
            f"{name}_ci_high": high}  # fmt: skip
