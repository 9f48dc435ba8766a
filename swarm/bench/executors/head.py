"""A Ray cluster on this machine, started as a user starts one (`ray start --head`) and stopped with
every process it started: the executors bench's running cluster, and the Ray tests'."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

from swarm.experiments.ray_head import RayHead


@contextlib.contextmanager
def ray_head(cpus: int, pythonpath: str) -> Iterator[tuple[str, int]]:
    """A head of `cpus` CPUs, no dashboard, whose workers import `pythonpath` first, with Ray's own
    settings: (its address, its session).  Its processes form a session of their own, all killed when
    the block ends."""
    with RayHead(cpus, pythonpath, settings={}) as head:
        yield head.address(), head.session
