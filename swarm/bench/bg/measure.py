"""`swarm bench bg`: the BG animat's parts and the whole of it, each as a time
per control period (250 ms) and a real-time factor, on one core: the GPR's
two loops for one period at their stable 1 ms Euler step, sensing (Prox
vectors from the camera), navigation (the map's observation, P, BKA and Expl
vectors, averaged over the ticks of a real run), the whole controller step,
and the world's tick beside it.  Each row is the median of several rounds
(the machine is shared and its speed drifts)."""

from __future__ import annotations

import time
from statistics import median

TARGET_REAL_TIME = 1000  # the target: one animat in-process, the GPR at its stable step included


def _engine(ticks: int):
    from swarm.engines.arena import ArenaEngine
    from swarm.scenario import load_scenario

    engine = ArenaEngine(load_scenario("bg-exp1").with_overrides(seed=1))
    engine.step(ticks)  # kernels compiled, a map made
    return engine


def _per_call(fn, repeat: int) -> float:
    t0 = time.perf_counter()
    for _ in range(repeat):
        fn()
    return (time.perf_counter() - t0) / repeat


def _timed_run(engine, ticks: int) -> tuple[int, float, float, float]:
    """(ticks run, seconds in the controller's step, in its navigation, in all): a real stretch of life."""
    c = engine.controllers[0]
    spent = [0.0, 0.0]

    def timed(fn, slot: int):
        def wrapper(*a, **k):
            t0 = time.perf_counter()
            out = fn(*a, **k)
            spent[slot] += time.perf_counter() - t0
            return out

        return wrapper

    parts = ("observe", "plan", "back_to_known", "explore", "learn")
    c.step = timed(type(c).step.__get__(c), 0)
    for name in parts:
        setattr(c.nav, name, timed(getattr(type(c.nav), name).__get__(c.nav), 1))
    try:
        t0 = time.perf_counter()
        ran = engine.step(ticks)
        total = time.perf_counter() - t0
    finally:
        del c.step
        for name in parts:
            delattr(c.nav, name)
    return ran, spent[0], spent[1], total


def bench_bg(quick: bool = False) -> dict:
    from agents.controllers.bg.senses import sense

    rounds, repeat, ticks = (3, 200, 400) if quick else (5, 1000, 2000)
    engine = _engine(200 if quick else 2000)
    period = engine.scenario.control_period
    rows: dict[str, list[float]] = {"gpr": [], "sensing": [], "navigation": [], "animat": [], "world": []}
    for _ in range(rounds):
        c = engine.controllers[0]
        p = engine.world.perceive()[0]
        s_d, s_v = c.last["s_dorsal"], c.last["s_ventral"]
        grey, heading = p["camera_grey"], float(p["compass"])
        rows["gpr"].append(_per_call(lambda c=c, s_d=s_d, s_v=s_v: c.bg.run(s_d, s_v, period), repeat))
        rows["sensing"].append(_per_call(lambda grey=grey, heading=heading: sense(grey, heading), repeat))
        ran, animat, navigation, total = _timed_run(engine, ticks)
        if ran == 0:  # the animat died: a fresh one
            engine = _engine(200)
            continue
        rows["navigation"].append(navigation / ran)
        rows["animat"].append(animat / ran)
        rows["world"].append((total - animat) / ran)
    out = {k: median(v) for k, v in rows.items() if v}
    return {"period_s": period, "ms": {k: round(v * 1000, 4) for k, v in out.items()},
            "real_time": {k: round(period / v) for k, v in out.items() if v > 0},
            "nodes": engine.controllers[0].nav.map.size, "rounds": rounds}  # fmt: skip


def format_bg_bench(r: dict) -> str:
    names = {"gpr": "GPR, both loops, one period (250 x 1 ms Euler)", "sensing": "sensing (Prox from the camera)",
             "navigation": "navigation (map, P, BKA, Expl), per tick", "animat": "the whole animat, one step",
             "world": "the world's tick (sensors, bodies, metabolism)"}  # fmt: skip
    lines = [f"bg animat on bg-exp1, one core, control period {r['period_s'] * 1000:.0f} ms; map of {r['nodes']} nodes",
             "", f"{'part':52s} {'ms':>9s} {'x real time':>12s}"]  # fmt: skip
    for k, label in names.items():
        if k in r["ms"]:
            lines.append(f"{label:52s} {r['ms'][k]:9.3f} {r['real_time'].get(k, 0):12,d}")
    animat_and_world = r["ms"]["animat"] + r["ms"]["world"]
    lines.append(f"{'animat + world (in-process engine)':52s} {animat_and_world:9.3f} "
                 f"{round(r['period_s'] * 1000 / animat_and_world):12,d}")  # fmt: skip
    factor = r["real_time"].get("animat", 0)
    verdict = "met" if factor >= TARGET_REAL_TIME else "not met"
    lines += ["", f"target: the whole animat at least {TARGET_REAL_TIME:,d}x real time: {factor:,d}x ({verdict})"]
    return "\n".join(lines)


__all__ = ["bench_bg", "format_bg_bench"]
