"""`swarm bench executors`: one real experiment through the local pool, through Ray started by the command, and
through a running Ray cluster, on this machine."""

from swarm.core.registry import BenchmarkSpec

BENCHMARKS = BenchmarkSpec(
    name="executors",
    description="an experiment through the local pool, Ray started by the command and a running Ray cluster, "
    "alternated: wall time, same rows",
    run="swarm.bench.executors.measure:bench_executors",
    report="swarm.bench.executors.measure:format_executors_bench",
)
