"""`swarm bench envs`: robot-steps per second of the arena's PettingZoo ParallelEnv."""

from swarm.core.registry import BenchmarkSpec

BENCHMARKS = BenchmarkSpec(
    name="envs",
    description="the arena ParallelEnv: 10 e-pucks with IR, random actions, robot-steps/s against 5,000",
    run="swarm.bench.envs.measure:bench_envs",
    report="swarm.bench.envs.measure:format_envs_bench",
)
