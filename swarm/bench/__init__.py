"""Benchmarks: one folder each, declaring its entry (BENCHMARKS, swarm.core.registry.BenchmarkSpec)
for `swarm bench NAME`; each measures throughput against its floor or peer in the same run."""

from swarm.core.registry import BenchmarkSpec, Registry

BENCHMARKS: Registry[BenchmarkSpec] = Registry("benchmark", "swarm.bench", "BENCHMARKS")
