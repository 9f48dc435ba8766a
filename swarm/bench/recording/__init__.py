"""`swarm bench recording`: what recording a run costs, in both runtimes."""

from swarm.core.registry import BenchmarkSpec

BENCHMARKS = BenchmarkSpec(
    name="recording",
    description="what recording costs",
    run="swarm.bench.recording.measure:bench_recording",
    report="swarm.bench.recording.measure:format_recording_bench",
)
