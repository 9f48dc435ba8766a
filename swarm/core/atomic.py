"""Files replaced whole or not at all: what a kill -9 or a power cut may interrupt.

The content goes to `<name>.tmp` beside the file, is fsynced, renamed over the
file, and the folder is fsynced so the rename itself is on disk.  A `.tmp` left
by a killed write is never read, and the next write overwrites it.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any


def replace(path: Path, write: Callable[[IO[Any]], None], text: bool = False) -> None:
    """`path` holds what `write(file)` writes, all of it, once this returns; before, its old content."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "w" if text else "wb", **({"newline": ""} if text else {})) as f:
        write(f)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)
    fsync_folder(path.parent)


def fsync_folder(folder: Path) -> None:
    """A rename on disk: without it a power cut may bring back the old name's content."""
    fd = os.open(folder, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
