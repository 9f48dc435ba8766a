"""`wander`: a reactive explorer for any robot model - drive ahead, turn away
from what the range sensors see in front, and now and then turn at random."""

from swarm.core.registry import ControllerSpec

CONTROLLERS = ControllerSpec(
    name="wander",
    world="arena",
    description="a reactive explorer: drive ahead, turn away from what is in front, now and then at random",
    example="zmaze",
    factory="agents.controllers.wander.controller:WanderController",
    parameters=("agents.controllers.wander.controller:WanderParams",),
    table="agents.controllers.wander.controller:WanderParams.from_table",
)
