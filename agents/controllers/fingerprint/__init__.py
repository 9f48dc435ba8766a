"""`fingerprint`: topological mapping and localization with fingerprints of
places (Tapus, Battaglia & Siegwart 2006): features from the camera and the
laser, circular global alignment with uncertainty, a topological map of mean
fingerprints with Markov localization (agents.controllers.navigation.topomap)."""

from swarm.core.registry import ControllerSpec

CONTROLLERS = ControllerSpec(
    name="fingerprint",
    world="arena",
    description="topological mapping and localization with fingerprints of places (Tapus et al. 2006)",
    records=("agents.controllers.navigation.recording:MapLog",),
    example="office",
    factory="agents.controllers.fingerprint.controller:FingerprintController",
    parameters=(
        "agents.controllers.fingerprint.params:FingerprintParams",
        "agents.controllers.fingerprint.params:FeatureParams",
        "agents.controllers.fingerprint.params:AlignParams",
        "agents.controllers.navigation.params:MapParams",
        "agents.controllers.navigation.params:GridParams",
        "agents.controllers.carrot.controller:CarrotParams",
        "agents.controllers.wander.controller:WanderParams",
    ),
    table="agents.controllers.fingerprint.controller:check_table",
    requires=("camera", "laser", "odometry", "compass"),
    shares="map",
    kernels=("agents.controllers.fingerprint.align", "agents.controllers.navigation.astar"),
)
