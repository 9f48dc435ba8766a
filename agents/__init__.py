"""Agents: the controllers (pure perception -> action kernels) and, later, the agent process."""

import swarm as _swarm  # noqa: F401  (configures the compiled-kernel cache first)
