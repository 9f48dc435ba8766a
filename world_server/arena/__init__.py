"""The arena world kind: a continuous floor of walls, zones and scheduled obstacles with
differential-drive robots; ray-cast sensing (raycast.py, sensors.py), bodies (drive.py), the BG
paper's metabolism, the scenario section, the summary, the world process's binding (server.py)
and the face its controllers see (face/).

`WORLD_KIND` declares the kind (world_server.WORLD_KINDS) and names its parts in every layer."""

from swarm.core.registry import WorldKindSpec

WORLD_KIND = WorldKindSpec(
    name="arena",
    description="a continuous floor of walls and zones, differential-drive robots with ray-cast sensors",
    example="zmaze",
    parse="world_server.arena.scenario:parse_section",
    server="world_server.arena.server:ArenaKind",
    runtime="agents.arena_runtime:ArenaAgentRuntime",
    open_recorder="swarm.recording.arena:open_for_server",
    goals="swarm.engines.goals:ArenaGoals",  # goals, routes, dwell and L_o (by A*), kept above the world
    run="swarm.cli_arena:run_arena",
    warm_up="swarm.engines.arena:warm_up",
    review="swarm.review.arena:arena_summary_from",
    plots="swarm.review.arena:write_arena_plots",
    metrics="swarm.recording.arena:ARENA_METRICS",
    schema="world_server.arena.schema:schema",
    progress=("reached", "with_goal"),
    options="swarm.cli_arena:add_arena_run_args",
    options_title="arena scenarios",
    overrides="swarm.cli_arena:arena_overrides",
    up_options="swarm.cli_arena:arena_up_options",
    print_summary="swarm.cli_arena:print_arena_summary",
    commands=("swarm.cli_arena:add_sense_parser",),
)
