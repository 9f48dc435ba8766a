"""Agents: the controllers (one package each) and the agent process that runs K of them."""

from swarm.core import jitcache as _jitcache  # noqa: F401  (configures the compiled-kernel cache first)
