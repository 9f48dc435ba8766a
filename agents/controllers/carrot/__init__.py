"""`carrot`: the DFT paper's baseline (Appendix B): A* on the map the robot is
given, then follow the carrot from the noisy position sensor and the compass."""

from swarm.core.registry import ControllerSpec

CONTROLLERS = ControllerSpec(
    name="carrot",
    world="arena",
    description="A* on the given map, then follow the carrot (the DFT paper's baseline)",
    example="zmaze",
    factory="agents.controllers.carrot.controller:CarrotController",
    parameters=("agents.controllers.carrot.controller:CarrotParams",),
    table="agents.controllers.carrot.controller:CarrotParams.from_table",
    requires=("position", "compass"),
    kernels=("agents.controllers.navigation.astar",),
)
