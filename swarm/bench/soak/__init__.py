"""`swarm bench soak`: a real-time `swarm up` with recording on, an agent process killed with SIGKILL every
few seconds and respawned; resident memory over the run, every tick in the recording, every loss counted."""

from swarm.core.registry import BenchmarkSpec, Option

BENCHMARKS = BenchmarkSpec(
    name="soak",
    description="a long real-time run with agent processes killed and respawned: memory, ticks, losses",
    run="swarm.bench.soak.measure:run",
    report="swarm.bench.soak.report:format_soak_bench",
    options=(
        Option("--minutes", "how long the run ticks (default 30)", type="swarm.core.tables:positive_number",
               default=30.0),
        Option("--kill-every", "seconds between SIGKILLs of an agent process (default 10)",
               type="swarm.core.tables:positive_number", metavar="S", default=10.0),
        Option("--kind", "the world kind soaked: grid (default) or arena", choices=("grid", "arena"),
               default="grid"),
        Option("--out", "a folder for the memory samples (soak.csv) and their plot (soak.png)", metavar="DIR"),
    ),
)  # fmt: skip
