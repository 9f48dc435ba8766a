"""`dft`: simultaneous planning and action with dynamic neural fields (Billing,
Lowe & Sandamirskaya 2015): an architecture declared as fields and couplings
(architecture.py), one engine that steps any such table (fields.py), and the
e-puck's faces to it (robot.py); every number with its provenance in params.py."""

from swarm.core.registry import ControllerSpec

CONTROLLERS = ControllerSpec(
    name="dft",
    world="arena",
    description="planning and acting with dynamic neural fields (Billing et al. 2015)",
    records=("agents.controllers.dft.recording:FieldLog",),
    example="zmaze",
    factory="agents.controllers.dft.controller:DftController",
    parameters=(
        "agents.controllers.dft.params:DftParams",
        "agents.controllers.dft.params:MapNoise",
        "agents.controllers.dft.params:SpaParams",
        "agents.controllers.dft.params:Interface",
        "agents.controllers.dft.params:SensorLayout",
    ),
    table="agents.controllers.dft.controller:check_table",
    requires=("position", "compass", "ir"),
    shares="context",
    kernels=("agents.controllers.dft.fields", "agents.controllers.navigation.astar"),
)
