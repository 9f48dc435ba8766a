"""swarm: a distributed multi-robot swarm simulator (c-marking foraging and friends).

From Python (docs/api.md): `swarm.run(scenario, ...)`, `swarm.load_scenario(ref)`,
`swarm.sweep(spec, ...)`; they are loaded when first used, so importing a part of swarm (an agent
process does) loads none of them."""

from swarm.core import jitcache as _jitcache  # noqa: F401  (first: where compiled kernels live)

__version__ = "0.1.0"
__all__ = ["load_scenario", "run", "sweep"]


def __getattr__(name: str):
    if name in __all__:
        from swarm import api

        return getattr(api, name)
    raise AttributeError(f"module 'swarm' has no attribute {name!r}")
