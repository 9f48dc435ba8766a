"""The worlds: one package per world kind (grid, arena), each with its controller face, and the
world process that serves any of them over zenoh."""

from swarm.core import jitcache as _jitcache  # noqa: F401  (configures the compiled-kernel cache first)
