"""`swarm bench distributed`: world and agent processes over zenoh, as a share of the bare lock-step floor
measured in the same command."""

from swarm.core.registry import BenchmarkSpec, Option

BENCHMARKS = BenchmarkSpec(
    name="distributed",
    description="world + agent processes",
    run="swarm.bench.distributed.measure:run",
    report="swarm.bench.distributed.measure:format_distributed_bench",
    options=(
        Option(
            "--pairs",
            "floor/run pairs measured in turn per size; the share is their median (default 3)",
            type="swarm.core.tables:positive",
            default=3,
        ),
    ),
)
