"""`swarm bench flood`: a short grid and arena run, unflooded and under a flood from separate processes;
tick latency of both, whether the result changed, and what the world dropped by reason."""

from swarm.core.registry import BenchmarkSpec, Option

BENCHMARKS = BenchmarkSpec(
    name="flood",
    description="tick latency and result under a flood of garbage, forged and repeated messages",
    run="swarm.bench.flood.measure:run",
    report="swarm.bench.flood.measure:format_flood_bench",
    options=(
        Option(
            "--pairs",
            "unflooded/flooded run pairs measured in turn per kind; the row is the median pair (default 3)",
            type="swarm.core.tables:positive",
            default=3,
        ),
        Option(
            "--rate",
            "messages a second the flooding clients send together (default 173000)",
            type="swarm.core.tables:positive",
            default=173_000,
        ),
    ),
)
