"""Ahead-of-time build of the controllers' step, for agent processes.

`import numba` alone costs an agent process 88 MB.  numba's pycc compiles
the very same `dispatch.answer_rows` (and everything it calls) and every
kernel the arena controllers declare with `swarm.core.kernels.exported` (A*, the
GPR loops, the alignments, the field steps) into a plain extension module.
Agent processes import that module, which needs only numpy, instead of the JIT.
The module is named after the source digest and lives in the compile cache
(swarm.core.jitcache), so an edited controller is rebuilt rather than run stale.
Building needs numba and a C compiler; when the build is missing, agent
processes fall back to the JIT (same step, more memory).

    python -m agents.controllers.aot     # build now (swarm up does it by itself)
"""

from __future__ import annotations

import fcntl
import importlib
import os
import shutil
import tempfile
from pathlib import Path

from agents.controllers import CONTROLLERS
from swarm.core.kernels import EXPORTS, built
from swarm.core.kernels import ahead_of_time_dir as build_dir
from swarm.core.kernels import ahead_of_time_module as module_name


def kernel_modules() -> list[str]:
    """Modules whose kernels agent processes call (swarm.core.kernels.exported): every controller's."""
    return sorted({module for spec in CONTROLLERS for module in spec.kernels})


def signature():
    """dispatch.answer_rows: kind, a message's blocks (read-only), memories, slot table, action rows, params,
    seed, tick, null."""
    from numba import types as t

    def message_block(dtype):
        return t.Array(dtype, 1, "C", readonly=True)

    return t.int64(t.int64, message_block(t.int64), message_block(t.float64), t.int64[:, ::1], t.int64[::1],
                   t.int64[:, ::1], t.float64[::1], t.int64, t.int64, t.boolean)  # fmt: skip


def envelope_signature():
    """envelope.answer_message: kind, the message (a Python `bytes`, read where it lies: a numpy view of it
    would cost an agent more than the rest of the call), memories, slot table, action rows, params, seed, null,
    the action message's bytes, info."""
    from numba import types as t

    return t.int64(t.int64, t.Bytes(t.uint8, 1, "C", readonly=True), t.int64[:, ::1], t.int64[::1],
                   t.int64[:, ::1], t.float64[::1], t.int64, t.boolean, t.uint8[::1], t.int64[::1])  # fmt: skip


def build() -> Path:
    """Compile the step module (about a minute on 2 cores) unless it exists."""
    if (done := built()) is not None:
        return done
    out = build_dir()
    out.mkdir(parents=True, exist_ok=True)
    with open(out / ".build.lock", "w") as lock:  # a second builder (another test worker or swarm up) waits,
        fcntl.flock(lock, fcntl.LOCK_EX)  # then finds the first one's module instead of compiling it again
        return built() or _compile(out)


def _compile(out: Path) -> Path:
    from numba.pycc import CC

    from agents.controllers.grid.dispatch import answer_rows
    from agents.controllers.grid.envelope import answer_message

    for module in kernel_modules():  # they declare their kernels on import
        importlib.import_module(module)
    with tempfile.TemporaryDirectory(dir=out) as tmp:  # concurrent builds: atomic rename at the end
        cc = CC(module_name())
        cc.output_dir = tmp
        cc.export("answer_rows", signature())(answer_rows.py_func)
        cc.export("answer_message", envelope_signature())(answer_message.py_func)
        for name, (kernel, sig) in sorted(EXPORTS.items()):
            cc.export(name, sig)(kernel.py_func)
        cc.compile()
        (result,) = Path(tmp).glob(f"{module_name()}.*.so")
        final = out / result.name
        os.replace(result, final)
    for stale in out.glob("swarm_steps_*"):
        if not stale.name.startswith(module_name()) and stale.is_file():
            stale.unlink(missing_ok=True)
    shutil.rmtree(out / "__pycache__", ignore_errors=True)
    return final


if __name__ == "__main__":
    print(build())
