"""`swarm bench fingerprint`: fingerprints of places: features, alignment, localization."""

from swarm.core.registry import BenchmarkSpec

BENCHMARKS = BenchmarkSpec(
    name="fingerprint",
    description="features, one alignment, localization against 20-1000 nodes",
    run="swarm.bench.fingerprint.measure:bench_fingerprint",
    report="swarm.bench.fingerprint.measure:format_fingerprint_bench",
)
