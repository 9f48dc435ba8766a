"""`swarm bench arena`: the arena's sensing and physics."""

from swarm.core.registry import BenchmarkSpec

BENCHMARKS = BenchmarkSpec(
    name="arena",
    description="sensing and physics of the arena",
    run="swarm.bench.arena.measure:bench_arena",
    report="swarm.bench.arena.measure:format_arena_bench",
)
