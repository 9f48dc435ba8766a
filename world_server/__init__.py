"""The worlds: one package per world kind (grid, arena), each with its controller face, and the
world process that serves any of them over zenoh.

`WORLD_KINDS` is the registry of world kinds: each kind's folder declares `WORLD_KIND`
(swarm.core.registry.WorldKindSpec) in its `__init__.py` as plain data, so reading the registry
loads no world.  The scenario loader, the world process, the agent runtimes, the engines' runs,
the recorder, the review, `swarm prepare` and the command line find a kind's parts through it, so
adding a world kind is adding its folder.  The default kind comes first, then the others by name.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from swarm.core import jitcache as _jitcache  # noqa: F401  (configures the compiled-kernel cache first)
from swarm.core.registry import Registry, WorldKindSpec

WORLD_KINDS: Registry[WorldKindSpec] = Registry(
    "world kind", "world_server", "WORLD_KIND", key=lambda kind: not kind.default
)


def world_kind(name: Any = None) -> WorldKindSpec:
    """The world kind called `name`, or the default kind when `name` is None
    (swarm.core.registry.UnknownPart, a ValueError naming the kinds, for an unknown one)."""
    if name is None:
        return next(k for k in WORLD_KINDS if k.default)
    return WORLD_KINDS[name]


def kind_of(thing: Any) -> WorldKindSpec:
    """The world kind of a scenario, a summary, a world's info or a recording's metadata: the
    one its `kind` names, or the default kind when it names none."""
    return world_kind(thing.get("kind") if isinstance(thing, Mapping) else getattr(thing, "kind", None))


def progress_keys(message: Mapping) -> tuple[str, str]:
    """(done, total): the progress keys of the world kind whose total a world's state or info
    message carries (the default kind's when it carries none)."""
    return next((k.progress for k in WORLD_KINDS if k.progress[1] in message), world_kind().progress)
