"""`swarm bench own`: a controller loaded from outside the package ("module:Class") beside the same
controller registered inside it."""

from swarm.core.registry import BenchmarkSpec

BENCHMARKS = BenchmarkSpec(
    name="own",
    description="wander copied out of the package and loaded as module:Class, beside the registered wander",
    run="swarm.bench.own.measure:bench_own",
    report="swarm.bench.own.measure:format_own_bench",
)
