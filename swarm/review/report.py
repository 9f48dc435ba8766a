"""Reading recordings back: `swarm report` and `swarm replay`.

Everything comes out of the .rrd through rerun's own reader
(`rerun.chunk.RrdReader`); there is no side file.  The summary is rebuilt from
the recorded time series and the run's metadata, so it checks what the
recording holds rather than repeating what the run said.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import quote

import numpy as np

from swarm.core.errors import RecordingError
from swarm.core.registry import resolve
from swarm.recording import frames
from world_server import kind_of


@dataclass
class Recording:
    path: Path
    meta: dict
    printed: dict | None  # the summary the run printed, if the run ended
    series: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)  # name -> (ticks, values)

    def values(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        return self.series.get(name, (np.zeros(0, np.int64), np.zeros(0)))

    def last(self, name: str, default: float = 0.0) -> float:
        values = self.values(name)[1]
        return float(values[-1]) if len(values) else default


def read_recording(path: str | Path) -> Recording:
    path = Path(path)
    if not path.is_file():
        raise RecordingError(f"{path}: no such file (recordings land in runs/<run-id>.rrd)")
    meta = printed = None
    parts: dict[str, list[tuple[np.ndarray, np.ndarray]]] = {}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # rerun warns before it fails on a cut file; we explain below
            chunks = _chunks(path)
        for chunk in chunks:
            entity = chunk.entity_path.lstrip("/")
            if entity == "run/meta" and chunk.is_static:
                meta = json.loads(_any_value(chunk, "meta"))
            elif entity == "run/summary" and chunk.is_static:
                printed = json.loads(_any_value(chunk, "summary"))
            elif entity.startswith("metrics/") and not chunk.is_static:
                batch = chunk.to_record_batch()
                ticks = batch.column("tick").to_numpy()
                values = batch.column("Scalars:scalars")
                if entity.startswith("metrics/robots/"):  # one scalar per robot and tick: (T, n)
                    values = np.array([np.asarray(v.as_py(), np.float64) for v in values])
                else:
                    values = values.flatten().to_numpy()
                parts.setdefault(entity.removeprefix("metrics/"), []).append((ticks, values))
            elif entity == "world/robots" and not chunk.is_static:
                batch = chunk.to_record_batch()
                ticks = batch.column("tick").to_numpy()
                xy = np.array([np.asarray(v.as_py(), np.float64) for v in batch.column("Points2D:positions")])
                parts.setdefault("positions", []).append((ticks, xy * [1.0, -1.0]))  # logged north up
    except Exception as exc:  # rerun raises its own types for broken files
        raise RecordingError(f"{path}: damaged or not a rerun recording ({exc}). If the run was killed, "
                             "the file may be cut short; rerun it to get a complete recording.") from None  # fmt: skip
    if meta is None:
        raise RecordingError(f"{path}: not a swarm recording (no run/meta); was it written by `swarm run --record` "
                             "or `swarm up`?")  # fmt: skip
    series = {}
    for name, chunks in parts.items():
        ticks = np.concatenate([t for t, _ in chunks])
        values = np.concatenate([v for _, v in chunks])
        order = np.argsort(ticks, kind="stable")
        series[name] = (ticks[order], values[order])
    rec = Recording(path, meta, printed, series)
    if printed is None:
        ticks = rec.values(kind_of(meta).progress[0])[0]
        upto = f"ticks 0..{int(ticks[-1])}" if len(ticks) else "no ticks"
        raise RecordingError(f"{path}: truncated: it holds {upto} but no end-of-run record (the run was "
                             "killed or is still going, or the file was cut).")  # fmt: skip
    return rec


def _chunks(path: Path) -> list:
    """The file's chunks; a file a kill cut inside a frame: those of its whole frames."""
    from rerun.chunk import RrdReader

    try:
        return list(RrdReader(path).stream())
    except Exception:  # rerun raises its own types for broken files
        with frames.whole_frames(path) as whole:
            if whole is None:
                raise
            return list(RrdReader(whole).stream())


def _any_value(chunk, column: str) -> str:
    return chunk.to_record_batch().column(column).flatten()[0].as_py()


# -------------------------------------------------------------------- summary


def summary_from(rec: Recording) -> dict:
    """The run summary (keys of `swarm run --json`, plus the distributed ones
    when the run was distributed), rebuilt from the recorded series by the
    review of the recording's world kind (world_server.WORLD_KINDS)."""
    return resolve(kind_of(rec.meta).review)(rec)


# ---------------------------------------------------------------------- plots


def write_plots(rec: Recording, out: Path) -> list[Path]:
    """The plots of the recording's world kind, written into `out`."""
    return resolve(kind_of(rec.meta).plots)(rec, out)


def report(path: str | Path, out: str | Path | None = None) -> dict:
    rec = read_recording(path)
    summary = summary_from(rec)
    out = Path(out) if out is not None else Path(path).with_suffix("")
    plots = write_plots(rec, out)
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    return {"summary": summary, "plots": [str(p) for p in plots], "out": str(out),
            "metrics": sorted(n for n in rec.series if n in resolve(kind_of(rec.meta).metrics))}  # fmt: skip


# --------------------------------------------------------------------- replay


def rerun_binary() -> str:
    """The viewer that ships with rerun-sdk (next to this Python), else on PATH."""
    local = Path(sys.executable).parent / "rerun"
    found = str(local) if local.exists() else shutil.which("rerun")
    if not found:
        raise RecordingError("the rerun viewer is not installed: run `make install` (it comes with rerun-sdk)")
    return found


def web_url(web_port: int, grpc_port: int, host: str = "127.0.0.1") -> str:
    return f"http://{host}:{web_port}/?url={quote(f'rerun+http://{host}:{grpc_port}/proxy', safe='')}"


def replay_command(path: Path, web: bool, web_port: int, grpc_port: int, bind: str) -> list[str]:
    if web:
        return [rerun_binary(), "--serve-web", "--bind", bind, "--web-viewer-port", str(web_port),
                "--port", str(grpc_port), str(path)]  # fmt: skip
    return [rerun_binary(), str(path)]


def replay(path: str | Path, web: bool = False, web_port: int = 9090, grpc_port: int = 9876,
           bind: str = "127.0.0.1") -> int:  # fmt: skip
    path = Path(path)
    read_recording(path)  # a clear error now beats a blank viewer
    if not web and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise RecordingError("no display here for the native viewer: use `swarm replay FILE --web` and open the URL")
    cmd = replay_command(path, web, web_port, grpc_port, bind)
    # Its own process group: the `rerun` launcher starts the viewer binary as a child, and
    # Ctrl-C or SIGTERM (a test, docker stop) must end both.
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    previous = signal.signal(signal.SIGTERM, _interrupt)
    if web:
        print(f"serving {path} — open {web_url(web_port, grpc_port)}  (Ctrl-C to stop)", flush=True)
    try:
        return proc.wait()
    except KeyboardInterrupt:
        return 0
    finally:
        signal.signal(signal.SIGTERM, previous)
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGTERM)
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)


def _interrupt(signum, frame):
    raise KeyboardInterrupt
