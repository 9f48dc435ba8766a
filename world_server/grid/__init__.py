"""The grid world kind (Simonin et al. 2007): cells of obstacles, resources, marks, trails and
pheromone; the tick rules (world.py), robot bodies (bodies.py), the scenario section
(scenario.py), the world process's binding (server.py) and the face its controllers see (face/).

`WORLD_KIND` declares the kind (world_server.WORLD_KINDS) and names its parts in every layer."""

from swarm.core.registry import WorldKindSpec

WORLD_KIND = WorldKindSpec(
    name="grid",
    description="cells of obstacles, resources and marks, robots that move cell to cell (the c-marking paper's)",
    example="setup2",
    default=True,  # a scenario file without `kind` is a grid
    parse="world_server.grid.scenario:parse_section",
    server="world_server.grid.server:GridKind",
    runtime="agents.grid_runtime:GridAgentRuntime",
    open_recorder="swarm.recording.grid:open_for_server",
    run="swarm.cli_grid:run_grid",
    warm_up="swarm.engines.grid:warm_up",
    review="swarm.review.grid:grid_summary_from",
    plots="swarm.review.grid:write_grid_plots",
    metrics="swarm.recording.grid:METRICS",
    schema="world_server.grid.schema:schema",
    progress=("delivered", "total"),
    options="swarm.cli_grid:add_grid_options",
    overrides="swarm.cli_grid:grid_overrides",
    check="world_server.grid.scenario:check_until",
    up_options="swarm.cli_grid:grid_up_options",
    print_summary="swarm.cli_grid:print_grid_summary",
)
