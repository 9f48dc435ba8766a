"""Where numba keeps compiled kernels: a directory keyed by the kernels' source.

Numba's own cache only notices edits to the file of the cached function, not
to the functions it calls from other files, so an edited controller could run
stale inside a cached engine loop.  Keying the cache directory on a hash of
every source file of the three packages makes any edit recompile everything.
NUMBA_CACHE_DIR, when set, is left alone.
"""

import hashlib
import os
from pathlib import Path

_PACKAGES = ("swarm", "agents", "world_server")


def source_digest() -> str:
    root = Path(__file__).resolve().parent.parent
    h = hashlib.sha1()
    for pkg in _PACKAGES:
        for path in sorted((root / pkg).rglob("*.py")):
            h.update(str(path.relative_to(root)).encode())
            h.update(path.read_bytes())
    return h.hexdigest()[:16]


def configure() -> None:
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    import numba

    base = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "swarm" / "numba"
    numba.config.CACHE_DIR = str(base / source_digest())


configure()
