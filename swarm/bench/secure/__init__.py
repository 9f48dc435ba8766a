"""`swarm bench secure`: how many forged and unauthenticated puts a secure run's router lets through
(the target: none), and what login, access rules and TLS cost a stream of puts."""

from swarm.core.registry import BenchmarkSpec, Option

BENCHMARKS = BenchmarkSpec(
    name="secure",
    description="forged and unauthenticated puts refused at the router; secure links' cost",
    run="swarm.bench.secure.measure:run",
    report="swarm.bench.secure.measure:format_secure_bench",
    options=(
        Option(
            "--forged",
            "forged puts per key of another agent process or of the world (default 1000)",
            type="swarm.core.tables:positive",
            default=1000,
        ),
    ),
)
