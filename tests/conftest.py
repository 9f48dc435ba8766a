"""How `pytest -n 2 --dist loadfile` shares the suite between its workers.

A test file is one unit of work, so the fixtures a module shares (a Docker image, a Ray
cluster, a secure run's credentials) are built once.  The files listed in `SPREAD` hold
independent tests, a few of them long (experiment smoke runs, kill -9 and resume runs): their
tests are handed out one by one, so that neither worker sits idle while the other finishes a
long file.  xdist's own `loadgroup` would say this with marks, but it no longer groups
anything on pytest 9 (pytest-dev/pytest-xdist#1386).
"""

from __future__ import annotations

import shutil

import pytest
from xdist.scheduler import LoadScopeScheduling

SPREAD = frozenset({
    "tests/test_registries.py",  # a test per controller, sensor, world kind, experiment and benchmark
    "tests/test_arena_distributed.py",
    "tests/test_distributed.py",
    "tests/test_reproduce.py",
    "tests/test_recording.py",
    "tests/test_own_grid_controllers.py",
})  # fmt: skip


class SpreadScheduling(LoadScopeScheduling):
    """`loadfile`, except that each test of a file in `SPREAD` is a unit of its own."""

    def _split_scope(self, nodeid: str) -> str:
        file = nodeid.split("::", 1)[0]
        return nodeid if file in SPREAD else file


def pytest_configure(config):
    """Build the agents' compiled step (agents/controllers/aot.py) before any test starts agent processes,
    as `swarm up` does: without it, every agent process of a test compiles its step with numba on its first
    observation (a minute of CPU each on a fresh source version), which on a loaded machine outlasts a
    world's wait for joins or holds a real-time run back.  Once, here in the session's controller."""
    if hasattr(config, "workerinput") or config.option.collectonly or getattr(config.option, "help", False):
        return  # an xdist worker (the controller built it before starting it), or no test to run
    if shutil.which("cc"):  # without a C compiler it cannot build: the JIT it is
        from swarm.launcher import finish_agents_build, start_agents_build

        finish_agents_build(start_agents_build())


@pytest.hookimpl(tryfirst=True, optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    if config.getvalue("dist") == "loadfile":
        return SpreadScheduling(config, log)
    return None
