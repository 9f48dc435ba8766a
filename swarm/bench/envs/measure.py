"""`swarm bench envs`: robot-steps per second of swarm.envs.parallel_env on 10 e-pucks with their IR
sensors in the Z-maze, random wheel speeds, in process on one thread, against the target of 5,000;
beside it the floor measured in the same rounds: the bare tick the env wraps (every robot perceives,
the world resolves the period, the goals are tracked), so the env's own cost per step is their
difference.  Each figure is the median of several timed rounds (the machine is shared)."""

from __future__ import annotations

import time
from statistics import median

import numpy as np

TARGET = 5000.0  # robot-steps/s
AGENTS = 10


def _env_round(env, actions: np.ndarray) -> float:
    """Robot-steps/s of env.step over the pre-drawn actions (an episode that ends is reset, untimed)."""
    done, seconds = 0, 0.0
    for row in actions:
        if not env.agents:
            env.reset()
        done += len(env.agents)
        t0 = time.perf_counter()
        env.step({name: row[int(name[6:])] for name in env.agents})
        seconds += time.perf_counter() - t0
    return done / seconds


def _floor_round(env, steps: int) -> float:
    """Robot-steps/s of the bare tick on the env's world (all robots acting, none holding)."""
    run = env.run
    wheels = np.zeros_like(run.actions)
    t0 = time.perf_counter()
    for _ in range(steps):
        run.world.perceive_groups()
        run.world.apply_all(wheels)
        run.goals.track(run.world)
    return steps * run.world.n / (time.perf_counter() - t0)


def bench_envs(quick: bool = False) -> dict:
    import numba

    from swarm.envs import parallel_env

    numba.set_num_threads(1)
    env = parallel_env("zmaze", agents=AGENTS, max_ticks=100_000, seed=0)
    env.reset(seed=0)
    limit = float(env.action_space("robot_0").high[0])
    steps = 300 if quick else 2000
    actions = np.random.default_rng(0).uniform(-limit, limit, (steps, AGENTS, 2)).astype(np.float32)
    _env_round(env, actions[:50])  # compiled kernels warm
    rates, floors = [], []
    for _ in range(3 if quick else 5):
        env.reset(seed=0)
        rates.append(_env_round(env, actions))
        env.reset(seed=0)
        floors.append(_floor_round(env, steps))
    rate, floor = median(rates), median(floors)
    return {
        "scenario": "zmaze", "agents": AGENTS, "sensors": sorted(env.observation_space("robot_0").spaces),
        "steps_per_round": steps, "robot_steps_per_s": round(rate), "floor_robot_steps_per_s": round(floor),
        "env_overhead_us_per_step": round((AGENTS / rate - AGENTS / floor) * 1e6, 1),
        "target_robot_steps_per_s": TARGET, "meets_target": rate >= TARGET,
    }  # fmt: skip


def format_envs_bench(result: dict) -> str:
    r = result
    head = "| env | robot-steps/s | target | bare tick robot-steps/s | env's own µs per step |\n|---|---|---|---|---|"
    row = (f"| ParallelEnv, {r['agents']} e-pucks ({', '.join(r['sensors'])}), {r['scenario']} | "
           f"{r['robot_steps_per_s']:,} | {r['target_robot_steps_per_s']:,.0f} "
           f"({'met' if r['meets_target'] else 'under'}) | {r['floor_robot_steps_per_s']:,} | "
           f"{r['env_overhead_us_per_step']} |")  # fmt: skip
    return f"swarm bench envs: random actions, in process, one thread\n\n{head}\n{row}"
