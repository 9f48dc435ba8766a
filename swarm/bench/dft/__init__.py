"""`swarm bench dft`: one step of the dynamic neural-field architecture."""

from swarm.core.registry import BenchmarkSpec

BENCHMARKS = BenchmarkSpec(
    name="dft",
    description="one step of the neural-field architecture at 100x100 and 210x210 cells",
    run="swarm.bench.dft.measure:bench_dft",
    report="swarm.bench.dft.measure:format_dft_bench",
)
