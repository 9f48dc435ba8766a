"""`swarm bench engine`: the in-process grid engine's throughput against its floor."""

from swarm.core.registry import BenchmarkSpec

BENCHMARKS = BenchmarkSpec(
    name="engine",
    description="the in-process engine",
    run="swarm.bench.engine.measure:bench_engine",
    report="swarm.bench.engine.measure:format_engine_bench",
)
