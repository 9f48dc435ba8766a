"""swarm: a distributed multi-robot swarm simulator (c-marking foraging and friends)."""

from swarm.core import jitcache as _jitcache  # noqa: F401  (first: where compiled kernels live)

__version__ = "0.1.0"
