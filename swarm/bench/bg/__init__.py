"""`swarm bench bg`: the basal-ganglia animat, as real-time factors."""

from swarm.core.registry import BenchmarkSpec

BENCHMARKS = BenchmarkSpec(
    name="bg",
    description="the animat's GPR loops, sensing, navigation and step, as real-time factors",
    run="swarm.bench.bg.measure:bench_bg",
    report="swarm.bench.bg.measure:format_bg_bench",
)
