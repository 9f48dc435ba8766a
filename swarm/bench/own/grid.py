"""`swarm bench own`'s grid half: the bundled `marking` step beside the same step loaded from outside.

marking's own module is copied into a temporary folder outside the package, beside a module that
declares it a GridController (world_server.grid.face.own) with the bundled memory layout and the
two lines the bundled dispatch adds around every step (a blocked move forgets where it came from;
the mode is reported).  Both run in process on the same scenario and seed: the bundled one in the
cached loop that dispatches on its kind code, the copy in the same loop compiled around its step
(with the check of every action a user's step gets).  Rounds alternate the two, each row is the
median of its rounds, and the two worlds must end identical."""

from __future__ import annotations

import time
from pathlib import Path
from statistics import median

SCENARIO = "setup3-50"  # 50 robots on a 50 x 50 grid
COPY = "copied_marking_controller:MARKING"
DECLARATION = '''"""The bundled marking step, loaded from outside the package (swarm bench own)."""

from numba import njit

from copied_marking import marking_step
from world_server.grid.face.layout import A_MODE, BLOCKED, M_MODE, M_PREV, MEM_LEN
from world_server.grid.face.own import GridController


@njit(cache=True)
def step(pi, pf, mem, act, params, seed, agent, tick):
    if pi[BLOCKED] != 0:
        mem[M_PREV] = -1
    marking_step(pi, pf, mem, act, params, seed, agent, tick)
    act[A_MODE] = mem[M_MODE]


MEMORY = tuple((f"w{k}", 1, -1 if k == M_PREV else 0) for k in range(MEM_LEN))
MARKING = GridController(step=step, memory=MEMORY, description="marking, copied out", marks=True)
'''


def write_copy(folder: Path) -> None:
    """marking's module and its declaration, into `folder` (to be put on sys.path)."""
    import importlib.util

    source = Path(importlib.util.find_spec("agents.controllers.grid.marking").origin)
    (folder / "copied_marking.py").write_text(source.read_text())
    (folder / "copied_marking_controller.py").write_text(DECLARATION)


def _timed(controller: str, ticks: int):
    from swarm.engines.grid import Engine
    from swarm.scenario import load_scenario

    engine = Engine(load_scenario(SCENARIO).with_overrides(controller=controller, seed=1))
    engine.step(5)  # kernels compiled or loaded, first-tick work done
    t0 = time.perf_counter()
    ran = engine.step(ticks, until="both")
    return (time.perf_counter() - t0) / max(ran, 1), engine


def bench_grid(quick: bool = False) -> dict:
    """Ticks per second of each, and whether the two runs ended in the same world."""
    ticks, rounds = (200, 3) if quick else (2000, 7)
    times: dict[str, list[float]] = {"marking": [], COPY: []}  # seconds per tick
    ends = {}
    for _ in range(rounds):
        for name in times:
            seconds, engine = _timed(name, ticks)
            times[name].append(seconds)
            ends[name] = engine
    registered, loaded = (median(v) for v in times.values())
    a, b = ends.values()
    same = bool((a.world.layers == b.world.layers).all() and (a.world.pos == b.world.pos).all())
    return {"scenario": SCENARIO, "robots": a.scenario.agents, "ticks": a.tick - 5, "rounds": rounds,
            "registered_us_per_tick": 1e6 * registered, "loaded_us_per_tick": 1e6 * loaded,
            "slowdown": loaded / registered - 1.0, "same_world": same}  # fmt: skip


def format_grid(r: dict) -> str:
    return (
        f"{r['robots']} marking robots on {r['scenario']}, {r['ticks']} ticks, median of {r['rounds']} rounds each:\n"
        f"  bundled      marking                            {r['registered_us_per_tick']:8.1f} us/tick\n"
        f"  module:NAME  {COPY}  {r['loaded_us_per_tick']:8.1f} us/tick\n"
        f"  loaded from outside: {100 * r['slowdown']:+.1f}% time; "
        f"worlds {'identical' if r['same_world'] else 'DIFFER'}"
    )
