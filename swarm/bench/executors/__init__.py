"""`swarm bench executors`: one real experiment through the local pool and through Ray on this machine."""

from swarm.core.registry import BenchmarkSpec

BENCHMARKS = BenchmarkSpec(
    name="executors",
    description="an experiment through the local pool and through Ray here, alternated: wall time, same rows",
    run="swarm.bench.executors.measure:bench_executors",
    report="swarm.bench.executors.measure:format_executors_bench",
)
