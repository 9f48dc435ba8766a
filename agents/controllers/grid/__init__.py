"""The grid controllers of Simonin et al. (2007): c-marking, the plain marking agents and the
pheromone ant baseline.  One compiled step serves all three (`dispatch.step_controller`, called by
both runtimes; `envelope` answers a whole observation message in one call); each controller is a
module of pure functions over the grid face's flat rows (world_server/grid/face/layout.py)."""

from swarm.core.registry import ControllerSpec

_KERNELS = ("swarm.core.rng",)
_PARAMS = "world_server.grid.params"  # the one declared parameter set of the three and of the bodies
_RULE = f"{_PARAMS}:MarkingRule"
_BODIES = f"{_PARAMS}:PhysicsParams"  # the robots' bodies, ideal (the paper) or physical

CONTROLLERS = (
    ControllerSpec(
        name="cmarking",
        world="grid",
        description="c-marking agents: marks that converge to the distance from the base, and trails (Simonin 2007)",
        factory="world_server.grid.face.layout:CMARKING",
        parameters=(_RULE, f"{_PARAMS}:CMarkingParams", _BODIES),
        kernels=_KERNELS,
    ),
    ControllerSpec(
        name="marking",
        world="grid",
        description="the marking agents alone: marks and their descent, no trails",
        factory="world_server.grid.face.layout:MARKING",
        parameters=(_RULE, _BODIES),
        kernels=_KERNELS,
    ),
    ControllerSpec(
        name="ant",
        world="grid",
        description="the pheromone ant baseline: pheromone laid and followed, evaporating and diffusing",
        factory="world_server.grid.face.layout:ANT",
        parameters=(f"{_PARAMS}:AntParams", _BODIES),
        kernels=_KERNELS,
    ),
)
