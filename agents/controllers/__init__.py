"""The controllers: one folder each (or one folder per compiled family: grid/), and the registry
that finds them.

A folder declares `CONTROLLERS`, its entries (swarm.core.registry.ControllerSpec: name, world
kind, factory, parameter table, sensors, shared key space, kernels, what it records), as plain
data: reading the registry imports no controller and no numba.  The command line, the scenario
loader, the recorder, the ahead-of-time build and the docs read it, so adding a controller is
adding its folder.  A user's arena controller needs no folder here: a scenario or `--controller`
names it "module:Class", or its package declares it in the entry point group `swarm.controllers`
(docs/controllers.md).  `navigation/` is a library the arena controllers share, not a controller.
"""

from swarm.core.registry import ControllerSpec, Registry

CONTROLLERS: Registry[ControllerSpec] = Registry(
    "controller", "agents.controllers", "CONTROLLERS", plugins="swarm.controllers", external=ControllerSpec.of_plugin
)
