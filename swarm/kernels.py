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

from collections.abc import Callable
from typing import Any

_AHEAD_OF_TIME = False
EXPORTS: dict[str, tuple[Any, str]] = {}  # name -> (the JIT dispatcher, its signature), for the build


def use_ahead_of_time() -> bool:
    """Kernels imported from now on come from the ahead-of-time module, when it
    is built for this source (else the JIT, as before).  Returns which."""
    global _AHEAD_OF_TIME
    from agents.controllers import aot

    _AHEAD_OF_TIME = aot.built() is not None
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
        from agents.controllers import aot

        built = aot.load(name)
        if built is None:
            raise ImportError(f"the agents' ahead-of-time module has no kernel {name!r}; rebuild it: "
                              "python -m agents.controllers.aot")  # fmt: skip
        return built

    return declare
