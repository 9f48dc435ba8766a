"""`swarm bench dft`: one control step of the whole SPA architecture (16
fields over the floor, 4 action fields, the proximity field, the e-puck's
inputs and wheels) at 100 x 100 cells (the Z-maze) and 210 x 210 (the large
maze), split into its parts, with the real-time factor against the 64 ms
step.  One core: scipy's transforms run on one worker, numba and numpy on
one thread.  Each row is the median of several timed rounds (the machine is
shared and its speed drifts), beside the floor measured in the same rounds:
the bare transforms a step cannot do without (every 2D field forward and back
once)."""

from __future__ import annotations

import time
from statistics import median

CASES = (("zmaze", "100x100"), ("large-maze", "210x210"))
STEP_S = 0.064


def _controller(name: str):
    from swarm.engines.arena import ArenaEngine
    from swarm.scenario import load_scenario

    engine = ArenaEngine(load_scenario(name).with_overrides(controller="dft", noise="low"))
    engine.step(20)  # compiled kernels and plans warm
    return engine.controllers[0], engine.world.perceive_all()[0]


def _transform_floor(shape: tuple[int, ...], fields: int, repeat: int) -> float:
    """Seconds for the bare transforms one step needs: every field forward and back once (float32),
    into buffers kept for them as the engine's are (a fresh 1-4 MB result a call doubles the time:
    the allocator hands such arrays back to the system and faults their pages in again)."""
    import numpy as np

    from agents.controllers.dft import pocketfft

    x = np.random.default_rng(0).random((fields, *shape), dtype=np.float32)
    axes = tuple(range(1, len(shape) + 1))
    spec = pocketfft.rfftn(x, axes)
    back = np.empty_like(x)
    pocketfft.irfftn(spec, shape, axes, back)
    t0 = time.perf_counter()
    for _ in range(repeat):
        pocketfft.rfftn(x, axes, spec)
        pocketfft.irfftn(spec, shape, axes, back)
    return (time.perf_counter() - t0) / repeat


def bench_dft(quick: bool = False) -> dict:
    rows = []
    for name, label in CASES:
        c, perception = _controller(name)
        grid = c.engine.groups[0]
        steps = 40 if quick else (200 if label == "100x100" else 80)
        rounds, floors = [], []
        for _ in range(3 if quick else 5):
            floors.append(_transform_floor(grid.shape, len(grid.fields), steps // 2))
            times: dict[str, float] = {}
            t0 = time.perf_counter()
            for _ in range(steps):
                c.step(perception, times)
            rounds.append(((time.perf_counter() - t0) / steps, {k: v / steps for k, v in times.items()}))
        total = median(r[0] for r in rounds)
        parts = {k: median(r[1][k] for r in rounds) for k in rounds[0][1]}
        fields = parts.get(f"fields {label}", 0.0)
        couplings = parts.get(f"couplings {label}", 0.0)
        action = parts.get("fields 100", 0.0) + parts.get("couplings 100", 0.0) + parts.get("wheels", 0.0)
        rows.append({
            "scenario": name, "cells": label, "step_ms": round(total * 1e3, 3),
            "fields_ms": round(fields * 1e3, 3), "couplings_ms": round(couplings * 1e3, 3),
            "action_fields_ms": round(action * 1e3, 3),
            "sensor_inputs_ms": round(parts.get("sensor inputs", 0) * 1e3, 3),
            "real_time_factor": round(STEP_S / total, 1),
            "transforms_floor_ms": round(median(floors) * 1e3, 3),  # the bare transforms, measured beside
            "step_over_floor": round(total / median(floors), 2),
        })  # fmt: skip
    return {"rows": rows, "step_s": STEP_S}


def format_dft_bench(result: dict) -> str:
    head = ("| fields | step ms | 2D fields (Euler, noise, sigmoid) | couplings (transforms, kernels, back) | "
            "action fields + wheels | sensor inputs | × real time (64 ms) | bare transforms ms | step / bare |\n"
            "|---|---|---|---|---|---|---|---|---|")  # fmt: skip
    lines = [head]
    for r in result["rows"]:
        lines.append(f"| {r['cells']} ({r['scenario']}) | {r['step_ms']} | {r['fields_ms']} | {r['couplings_ms']} | "
                     f"{r['action_fields_ms']} | {r['sensor_inputs_ms']} | {r['real_time_factor']} | "
                     f"{r['transforms_floor_ms']} | {r['step_over_floor']} |")  # fmt: skip
    return "\n".join(lines)
