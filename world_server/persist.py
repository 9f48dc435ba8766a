"""The world's state on disk: what a restarted world resumes from.

One `.npz` per run id, written atomically (temporary file, then rename) so a
kill -9 in the middle of a write leaves the previous snapshot intact.  The
scenario is stored with it: resuming a run under another scenario is refused.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

ARRAYS = ("layers", "pher", "pos", "payload", "blocked", "counters", "acts")


def state_path(state_dir: str | Path, run_id: str) -> Path:
    return Path(state_dir) / f"{run_id}.state.npz"


def save(path: Path, world, tick: int, slots: np.ndarray, stats: dict, scenario: dict, **extra: np.ndarray) -> None:
    """The grid world's arrays, the slots, and `extra` arrays (the controllers' memory)."""
    arrays = {"slots": slots, "body_xy": world.body_xy, **{k: getattr(world, k) for k in ARRAYS}, **extra}
    save_arrays(path, arrays, {"tick": tick, "stats": stats, "scenario": scenario})


def save_arrays(path: Path, arrays: dict, meta: dict) -> None:
    """Any world kind's state: its arrays and a JSON meta, written atomically."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "wb") as f:
        np.savez(f, meta=np.array(json.dumps(meta)), **arrays)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


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
    if not path.exists():
        return None
    with np.load(path, allow_pickle=False) as data:
        arrays = {k: data[k].copy() for k in data.files if k != "meta"}
        meta = json.loads(str(data["meta"]))
    return arrays, meta


def load(path: Path) -> dict | None:
    loaded = load_arrays(path)
    if loaded is None:
        return None
    arrays, meta = loaded
    return {**arrays, **meta}
