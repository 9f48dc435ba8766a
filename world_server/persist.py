"""The world's state on disk: what a restarted world resumes from.

One `.npz` per run id, replaced whole (swarm.core.atomic: a fsynced `.tmp`, renamed,
the folder fsynced), so a kill -9 or a power cut in the middle of a write leaves the
previous whole snapshot.  The file carries a SHA-256 of its
content and a format number: a cut, damaged or foreign file is refused in one line
(`StateError`) rather than resumed from.  The scenario is stored with it: resuming
a run under another scenario is refused.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import struct
import zipfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from swarm.core import atomic
from swarm.core.errors import StateError

FORMAT = 1  # bumped when the saved content changes: a file of another format is refused
CHECK = "checksum"  # the entry holding {"format", "sha256"}; its own bytes are not hashed
FIX = "delete it to start the run over, or point --state-dir elsewhere"
ARRAYS = ("layers", "pher", "pos", "payload", "blocked", "counters", "acts")


def state_path(state_dir: str | Path, run_id: str) -> Path:
    return Path(state_dir) / f"{run_id}.state.npz"


def save(path: Path, world, tick: int, slots: np.ndarray, stats: dict, scenario: dict, **extra: np.ndarray) -> None:
    """The grid world's arrays, the slots, and `extra` arrays (the controllers' memory)."""
    arrays = {"slots": slots, "body_xy": world.body_xy, **{k: getattr(world, k) for k in ARRAYS}, **extra}
    save_arrays(path, arrays, {"tick": tick, "stats": stats, "scenario": scenario})


def save_arrays(path: Path, arrays: dict, meta: dict) -> None:
    """Any world kind's state: its arrays and a JSON meta, written atomically."""
    text = json.dumps(meta)
    check = json.dumps({"format": FORMAT, "sha256": digest(text, arrays)})
    atomic.replace(path, lambda f: np.savez(f, meta=np.array(text), **{CHECK: np.array(check)}, **arrays))


def digest(meta: str, arrays: dict) -> str:
    """SHA-256 of the meta and of every array's name, dtype, shape and bytes, in name order."""
    h = hashlib.sha256(meta.encode())
    for name in sorted(arrays):
        a = np.asarray(arrays[name])
        h.update(f"\0{name}\0{a.dtype.str}\0{a.shape}\0".encode())
        h.update(np.ascontiguousarray(a).reshape(-1).view(np.uint8))  # its bytes where they lie: no copy of MBs
    return h.hexdigest()


def pack_blobs(blobs: list[bytes | None]) -> tuple[np.ndarray, np.ndarray]:
    """Byte strings as one uint8 array and (offset, length) rows; length -1: none."""
    at = np.zeros((len(blobs), 2), np.int64)
    offset = 0
    for i, blob in enumerate(blobs):
        at[i] = (offset, -1) if blob is None else (offset, len(blob))
        offset += 0 if blob is None else len(blob)
    joined = b"".join(b for b in blobs if b is not None)
    return np.frombuffer(joined, np.uint8).copy(), at


def unpack_blobs(joined: np.ndarray, at: np.ndarray) -> list[bytes | None]:
    raw = joined.tobytes()
    return [None if n < 0 else raw[o : o + n] for o, n in at.tolist()]


def load_arrays(path: Path) -> tuple[dict, dict] | None:
    """The arrays and meta saved at `path` (None: no file), refused (`StateError`) unless whole and checked."""
    path = Path(path)
    if not path.exists():
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            if not hasattr(data, "files"):
                raise ValueError("not an .npz archive")
            arrays = {k: data[k].copy() for k in data.files if k not in ("meta", CHECK)}
            text = str(data["meta"]) if "meta" in data.files else None
            check = json.loads(str(data[CHECK])) if CHECK in data.files else None
            meta = json.loads(text) if text is not None else None
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, struct.error, NotImplementedError) as exc:
        raise refused(path, f"is cut short or damaged ({type(exc).__name__}: {_first_line(exc)})") from None
    if text is None or not isinstance(meta, dict):
        raise refused(path, "has no meta")
    if not isinstance(check, dict) or "sha256" not in check:
        raise refused(path, "has no checksum (an older format or not written by swarm)")
    if check.get("format") != FORMAT:
        raise refused(path, f"is of format {check.get('format')!r}; this swarm reads format {FORMAT}")
    if check["sha256"] != digest(text, arrays):
        raise refused(path, "fails its checksum (damaged)")
    return arrays, meta


def refused(path: Path, problem: str) -> StateError:
    """One line: which file, what is wrong, what to do."""
    return StateError(f"{path}: saved state {problem}; {FIX}")


def _first_line(exc: BaseException) -> str:
    lines = str(exc).strip().splitlines()
    return lines[0][:120] if lines else ""


def load(path: Path) -> dict | None:
    loaded = load_arrays(path)
    if loaded is None:
        return None
    arrays, meta = loaded
    return {**arrays, **meta}


@contextlib.contextmanager
def resuming(path: Path) -> Iterator[None]:
    """Around a world kind's resume: a checked file that lacks what the kind reads (written by
    another world kind or swarm version) is refused in one line, not a KeyError."""
    try:
        yield
    except KeyError as exc:
        raise refused(path, f"lacks {exc.args[0]!r} (written by another world kind or swarm version)") from None
