"""Grid controllers: `layout` (the contract), one module per controller, and
`dispatch.step_controller`, the one compiled step both runtimes call.

Nothing is imported here, so `world_server.grid.face.layout` loads without numba
(agent processes run an ahead-of-time build of the step: `aot`)."""
