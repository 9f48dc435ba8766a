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

ARRAYS = ("layers", "pher", "pos", "payload", "blocked", "counters")


def state_path(state_dir: str | Path, run_id: str) -> Path:
    return Path(state_dir) / f"{run_id}.state.npz"


def save(path: Path, world, tick: int, slots: np.ndarray, stats: dict, scenario: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    meta = json.dumps({"tick": tick, "stats": stats, "scenario": scenario})
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "wb") as f:
        np.savez(f, slots=slots, meta=np.array(meta), body_xy=world.body_xy, **{k: getattr(world, k) for k in ARRAYS})
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def load(path: Path) -> dict | None:
    if not path.exists():
        return None
    with np.load(path, allow_pickle=False) as data:
        state = {k: data[k].copy() for k in (*ARRAYS, "slots", "body_xy")}
        state.update(json.loads(str(data["meta"])))
    return state
