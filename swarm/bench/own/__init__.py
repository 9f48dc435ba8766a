"""`swarm bench own`: a controller loaded from outside the package ("module:Class") beside the same
controller registered inside it."""

from swarm.core.registry import BenchmarkSpec

BENCHMARKS = BenchmarkSpec(
    name="own",
    description="wander and the grid's marking step copied out of the package and loaded from outside, beside "
    "the registered ones",
    run="swarm.bench.own.measure:bench_own",
    report="swarm.bench.own.measure:format_own_bench",
)
