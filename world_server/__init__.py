"""The world: the authoritative grid and the rules that apply agents' actions."""

import swarm as _swarm  # noqa: F401  (configures the compiled-kernel cache first)
