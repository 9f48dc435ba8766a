"""Where numba keeps compiled kernels: a directory keyed by the kernels' source.

Numba's own cache only notices edits to the file of the cached function, not
to the functions it calls from other files, so an edited controller could run
stale inside a cached engine loop.  Keying the cache directory on a hash of
every source file of the three packages makes any edit recompile everything.
NUMBA_CACHE_DIR, when set, is left alone.  Configured through the environment
(numba reads it when first imported), so importing swarm does not load numba:
agent processes run without it (agents/controllers/aot.py).
"""

import functools
import hashlib
import os
from pathlib import Path

_PACKAGES = ("swarm", "agents", "world_server")
_ROOT = Path(__file__).resolve().parents[2]  # the folder holding the three packages


def source_files() -> list[Path]:
    """Every source file of the three packages, in a fixed order."""
    return [path for pkg in _PACKAGES for path in sorted((_ROOT / pkg).rglob("*.py"))]


@functools.cache
def source_digest() -> str:
    h = hashlib.sha1()
    for path in source_files():
        h.update(str(path.relative_to(_ROOT)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def cache_root() -> Path:
    """Compiled artefacts of this exact source: ~/.cache/swarm/<digest>."""
    base = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "swarm"
    return base / source_digest()


def configure() -> None:
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    os.environ["NUMBA_CACHE_DIR"] = str(cache_root() / "numba")
    import sys

    if "numba" in sys.modules:  # imported before swarm: too late for the environment
        sys.modules["numba"].config.CACHE_DIR = os.environ["NUMBA_CACHE_DIR"]


configure()
