"""The Python face of `swarm run`: a run from a script or a notebook, with the same options, the
same checks and the same summary as the command, and its per-tick metrics as arrays.

A keyword is the command's option of the same name (`max_ticks=200` is `--max-ticks 200`;
`until="converged"`, `noise="high"`, `physics="physical"`, `start=(0.2, 0.5)`), parsed by the
command's own parser, so an option the command refuses is refused here in one line (ValueError).
The per-tick metrics are read back from the run's recording (the series `swarm report` plots),
so they are what a recorded run keeps, tick for tick."""

from __future__ import annotations

import argparse
import contextlib
import io
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np


@dataclass
class RunResult:
    """A finished run: its summary (what `swarm run --json` prints), the ticks its metrics were taken
    at, and each metric's value per tick (the world kind's series: arena `reached`, `collisions`,
    `distance`, `agents_alive`, ...; grid `delivered`, `explored`, ...), and the recording if kept."""

    summary: dict[str, Any]
    ticks: np.ndarray
    metrics: dict[str, np.ndarray] = field(default_factory=dict)
    recording: Path | None = None


def load_scenario(ref: str | Path):
    """A scenario: a preset (setup1, setup2, setup3-SIZE), a bundled name (zmaze, office, ...) or a
    TOML file; ScenarioError in one line for a bad one."""
    from swarm.scenario import load_scenario as load

    return load(str(ref))


def _argv(options: dict[str, Any]) -> list[str]:
    argv: list[str] = []
    for key, value in options.items():
        if value is None or value is False:
            continue
        flag = "--" + key.replace("_", "-")
        if value is True:
            argv.append(flag)
        elif isinstance(value, list | tuple):  # --flag=value: a value may start with a minus sign
            argv.append(f"{flag}={','.join(repr(float(v)) for v in value)}")
        else:
            argv.append(f"{flag}={value}")
    return argv


def _arguments(ref: str, options: dict[str, Any]) -> argparse.Namespace:
    """The `swarm run` namespace of these options; ValueError with the parser's one line if refused."""
    from swarm.cli import build_parser

    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err):
            return build_parser().parse_args(["run", ref, *_argv(options), "--json"])
    except SystemExit:
        lines = err.getvalue().strip().splitlines()
        last = lines[-1].removeprefix("swarm run: error: ").removeprefix("swarm: error: ") if lines else "bad options"
        raise ValueError(last) from None


def run(scenario, *, controller: str | None = None, agents: int | None = None, seed: int | None = None,
        record: str | Path | None = None, metrics: bool = True, **options: Any) -> RunResult:  # fmt: skip
    """Run `scenario` (a name, a file or a loaded scenario) in this process and return its result.

    `controller` is a registered name or your own "module:Class"; `record` keeps the recording at
    that path (otherwise a temporary one gives the metrics, or none is made with metrics=False)."""
    from swarm.cli import resolve_scenario
    from world_server import kind_of

    ref = scenario if isinstance(scenario, str | Path) else getattr(scenario, "name", "scenario")
    args = _arguments(str(ref), {"controller": controller, "agents": agents, "seed": seed, **options})
    loaded = resolve_scenario(args, None if isinstance(scenario, str | Path) else scenario)
    kind = kind_of(loaded)
    with tempfile.TemporaryDirectory(prefix="swarm-run-") as tmp:
        path = Path(record) if record is not None else (Path(tmp) / "run.rrd" if metrics else None)
        args.record = None if path is None else str(path)
        from swarm.core.registry import resolve

        summary = resolve(kind.run)(loaded, args, None)
        ticks, series = (np.zeros(0, np.int64), {}) if path is None else _series(path, kind.metrics)
    return RunResult(summary, ticks, series, Path(record) if record is not None else None)


def _series(path: Path, names_ref: str) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    from swarm.core.registry import resolve
    from swarm.review.report import read_recording

    recording = read_recording(path)
    out, ticks = {}, np.zeros(0, np.int64)
    for name in resolve(names_ref):
        t, values = recording.values(name)
        if len(t):
            ticks, out[name] = t, values
    return ticks, out


def sweep(spec, **kw):
    """`swarm sweep` from Python: `spec` is a sweep file's path or its tables as a dict (swarm.sweeps)."""
    from swarm.sweeps import sweep as run_sweep

    return run_sweep(spec, **kw)
