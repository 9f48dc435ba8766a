"""`bg`: basal-ganglia action selection and navigation for a surviving animat
(Girard et al. 2005): the GPR loops (gpr.py), the animat's senses
(senses.py), its saliences (saliences.py) and its map (places.py, on the
shared topological map)."""

from swarm.core.registry import ControllerSpec

CONTROLLERS = ControllerSpec(
    name="bg",
    world="arena",
    description="the basal-ganglia animat that survives on two resources (Girard et al. 2005)",
    records=("agents.controllers.navigation.recording:MapLog", "agents.controllers.bg.recording:ChannelLog"),
    example="bg-exp1",
    factory="agents.controllers.bg.controller:BgController",
    parameters=(
        "agents.controllers.bg.params:BgParams",
        "agents.controllers.bg.params:GprParams",
        "agents.controllers.bg.params:SalienceWeights",
        "agents.controllers.bg.params:SenseParams",
        "agents.controllers.bg.params:NavParams",
        "agents.controllers.navigation.params:MapParams",
        "world_server.arena.metabolism:MetabolismParams",
    ),
    table="agents.controllers.bg.controller:check_table",
    requires=("camera", "sonar", "odometry", "compass"),
    shares="map",
    kernels=(
        "agents.controllers.bg.gpr",
        "agents.controllers.bg.senses",
        "agents.controllers.bg.saliences",
        "agents.controllers.bg.places",
        "agents.controllers.navigation.dijkstra",
    ),
)
