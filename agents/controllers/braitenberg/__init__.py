"""`braitenberg`: the e-puck's classic obstacle avoidance, a Braitenberg vehicle wiring its eight
infrared sensors straight to its two wheels (the Webots e-puck demonstration controller)."""

from swarm.core.registry import ControllerSpec

CONTROLLERS = ControllerSpec(
    name="braitenberg",
    world="arena",
    description="the e-puck's Braitenberg obstacle avoidance: eight IR readings weighted straight onto the wheels",
    example="zmaze",
    factory="agents.controllers.braitenberg.controller:BraitenbergController",
    parameters=("agents.controllers.braitenberg.controller:BraitenbergParams",),
    table="agents.controllers.braitenberg.controller:BraitenbergParams.from_table",
    requires=("ir",),
)
