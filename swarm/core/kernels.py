"""Compiled kernels, with numba's JIT or without numba in the process.

`import numba` alone costs a process 88 MB.  The world and `swarm run` compile
kernels with the JIT, as always.  An agent process calls `use_ahead_of_time()`
before it imports its controller: from then on `njit` leaves functions as
they are, and each kernel that Python code calls is the function of the same
name in the agents' ahead-of-time module (agents/controllers/aot.py), which
numba's pycc compiled from this very source.  A kernel module declares such a
kernel once, with the signature the ahead-of-time build needs:

    @exported("bg_run_loops", "void(float64[:, :], ...)")
    @njit(cache=True)
    def run_loops(...): ...
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from swarm.core.jitcache import cache_root, source_digest

_AHEAD_OF_TIME = False
EXPORTS: dict[str, tuple[Any, str]] = {}  # name -> (the JIT dispatcher, its signature), for the build


def ahead_of_time_module() -> str:
    """The ahead-of-time module's name: one per version of the source."""
    return f"swarm_steps_{source_digest()}"


def ahead_of_time_dir() -> Path:
    return cache_root() / "aot"


def built() -> Path | None:
    """The ahead-of-time module built for this source (agents/controllers/aot.py builds it), or None."""
    return next(iter(sorted(ahead_of_time_dir().glob(f"{ahead_of_time_module()}.*.so"))), None)


def load(name: str = "answer_rows"):
    """A compiled function of the ahead-of-time module (`answer_rows`, `astar`), or None when it
    has not been built for this source."""
    path = built()
    if path is None:
        return None
    if str(path.parent) not in sys.path:
        sys.path.insert(0, str(path.parent))
    try:
        return getattr(importlib.import_module(ahead_of_time_module()), name)
    except (ImportError, AttributeError):
        return None


def use_ahead_of_time() -> bool:
    """Kernels imported from now on come from the ahead-of-time module, when it
    is built for this source (else the JIT, as before).  Returns which."""
    global _AHEAD_OF_TIME
    _AHEAD_OF_TIME = built() is not None
    return _AHEAD_OF_TIME


def njit(*args, **kwargs):
    """numba.njit, or, ahead of time, the plain function (only exported kernels are called)."""
    if _AHEAD_OF_TIME:
        if len(args) == 1 and callable(args[0]) and not kwargs:
            return args[0]
        return lambda fn: fn
    from numba import njit as numba_njit

    return numba_njit(*args, **kwargs)


def exported(name: str, signature: str) -> Callable:
    """A kernel Python code calls: registered for the ahead-of-time build, and
    replaced by the built one in an agent process."""

    def declare(kernel):
        if not _AHEAD_OF_TIME:
            EXPORTS[name] = (kernel, signature)
            return kernel
        compiled = load(name)
        if compiled is None:
            raise ImportError(f"the agents' ahead-of-time module has no kernel {name!r}; rebuild it: "
                              "python -m agents.controllers.aot")  # fmt: skip
        return compiled

    return declare
