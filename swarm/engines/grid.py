"""The in-process engine: the whole swarm in one process, compiled with numba.

It is both the fast tool for experiments and the yardstick of the distributed
runtime: it runs exactly the tick of world_server.grid.world (perceive all, decide
all, apply in agent-id order) with the controllers' own compiled steps.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np
from numba import njit

from agents.controllers.grid.dispatch import call_step, own_step
from swarm.core.errors import RunError
from swarm.recording.layer_classes import K_MARKS, K_RESOURCES, K_TRAILS, class_image
from world_server.grid.face.layout import A_MODE, PERC_F_LEN, PERC_LEN, controller_kind
from world_server.grid.face.own import compile_line, own_controller, run_memory, run_params
from world_server.grid.scenario import Layout, Scenario, check_until
from world_server.grid.world import (
    C_EXPLORED,
    C_OPTIMAL,
    C_REJECTED,
    L_MARK,
    L_RES,
    L_TRAIL,
    UNTIL,
    GridWorld,
    is_done,
    perceive,
    resolve_tick,
)

DEFAULT_MAX_ITERATIONS = 1_000_000
RECORDED_LAYERS = (L_MARK, L_TRAIL, L_RES)  # the grid layers a recording holds per tick, of these class kinds:
assert (K_MARKS, K_TRAILS, K_RESOURCES) == (0, 1, 2)


@njit(cache=True)
def decide_all(kind, layers, pher, pher_on, base_r, base_c, pos, payload, blocked, mem, acts, cparams, seed, tick,
               pi, pf):  # fmt: skip
    """`decide_with` the bundled controllers' step (cached)."""
    decide_with(None, kind, layers, pher, pher_on, base_r, base_c, pos, payload, blocked, mem, acts, cparams,
                seed, tick, pi, pf)  # fmt: skip


@njit
def decide_with(step, kind, layers, pher, pher_on, base_r, base_c, pos, payload, blocked, mem, acts, cparams, seed,
                tick, pi, pf):  # fmt: skip
    """Steps 1-2 of the tick: every agent perceives the start-of-tick world and chooses (`step(kind, ...)`,
    None for the bundled step: agents.controllers.grid.dispatch.call_step)."""
    for a in range(pos.shape[0]):
        perceive(layers, pher, pher_on, base_r, base_c, pos[a, 0], pos[a, 1], payload[a], blocked[a], pi, pf)
        call_step(step, kind, pi, pf, mem[a], acts[a], cparams, seed, a, tick)


@njit(cache=True)
def record_tick(t, layers, pos, payload, acts, counters, rec_pos, rec_mode, rec_payload, rec_counters, rec_last,
                rec_layers, rec_changed, rec_scales, rec_levels):  # fmt: skip
    """Copy tick t of a block into the recording buffers; a recorded layer is
    kept, as its class image (swarm.recording.layer_classes), only when it differs from
    the last copy (most ticks change little)."""
    rec_pos[t] = pos
    rec_mode[t] = acts[:, A_MODE]
    rec_payload[t] = payload
    rec_counters[t] = counters
    for k in range(len(RECORDED_LAYERS)):
        layer = layers[RECORDED_LAYERS[k]]
        last = rec_last[k]
        changed = False
        for r in range(layer.shape[0]):
            for c in range(layer.shape[1]):
                if layer[r, c] != last[r, c]:
                    changed = True
                    break
            if changed:
                break
        rec_changed[t, k] = changed
        if changed:
            last[:, :] = layer
            class_image(k, layer, rec_scales[k], rec_levels[k], rec_layers[t, k])


@njit(cache=True)
def run_ticks(
    kind, layers, pher, pher_scratch, base_r, base_c, pos, payload, blocked, mem, acts,
    cparams, wparams, counters, pher_on, seed, tick0, n_ticks, until, total, reachable,
    record, rec_pos, rec_mode, rec_payload, rec_counters, rec_last, rec_layers, rec_changed, rec_scales, rec_levels,
):  # fmt: skip
    """`run_ticks_with` the bundled controllers' step (cached)."""
    return run_ticks_with(
        None, kind, layers, pher, pher_scratch, base_r, base_c, pos, payload, blocked, mem, acts,
        cparams, wparams, counters, pher_on, seed, tick0, n_ticks, until, total, reachable,
        record, rec_pos, rec_mode, rec_payload, rec_counters, rec_last, rec_layers, rec_changed, rec_scales, rec_levels,
    )  # fmt: skip


@njit
def run_ticks_with(
    step, kind, layers, pher, pher_scratch, base_r, base_c, pos, payload, blocked, mem, acts,
    cparams, wparams, counters, pher_on, seed, tick0, n_ticks, until, total, reachable,
    record, rec_pos, rec_mode, rec_payload, rec_counters, rec_last, rec_layers, rec_changed, rec_scales, rec_levels,
):  # fmt: skip
    """Run up to n_ticks ticks from tick0; stop early once `until` holds.
    Returns the number of ticks run.  With `record`, tick t of the call is
    copied into the rec_* buffers (see swarm.recording.grid.EngineTap)."""
    pi, pf = np.empty(PERC_LEN, np.int64), np.empty(PERC_F_LEN, np.float64)
    for t in range(n_ticks):
        tick = tick0 + t
        decide_with(step, kind, layers, pher, pher_on, base_r, base_c, pos, payload, blocked, mem, acts, cparams, seed,
                    tick, pi, pf)  # fmt: skip
        resolve_tick(layers, pher, pher_scratch, base_r, base_c, pos, payload, acts, tick, wparams, counters, pher_on)
        if record:
            record_tick(t, layers, pos, payload, acts, counters, rec_pos, rec_mode, rec_payload, rec_counters,
                        rec_last, rec_layers, rec_changed, rec_scales, rec_levels)  # fmt: skip
        if is_done(until, counters, total, reachable):
            return t + 1
    return n_ticks


_NO_RECORDING = (np.zeros((0, 0, 2), np.int64), np.zeros((0, 0), np.int64), np.zeros((0, 0), np.int64),
                 np.zeros((0, 0), np.int64), np.zeros((0, 0, 0), np.int64), np.zeros((0, 0, 0, 0), np.uint16),
                 np.zeros((0, 0), np.bool_), np.zeros(3, np.int64), np.ones(3, np.int64))  # fmt: skip


@dataclass
class RunResult:
    summary: dict[str, Any]

    @property
    def iterations(self) -> int:
        return int(self.summary["iterations"])

    @property
    def finished(self) -> bool:
        return bool(self.summary["finished"])


class Engine:
    """A seeded swarm on one grid.  `run()` to completion or `step(n)` ticks."""

    def __init__(self, scenario: Scenario, layout: Layout | None = None):
        self.scenario = scenario
        self.own = own = own_controller(scenario)
        # the loops of the bundled step (cached), or the same loops compiled around a user's step
        self.kind = controller_kind(scenario.controller) if own is None else own.step
        self._run_ticks = run_ticks if own is None else partial(run_ticks_with, own_step)
        self._decide = decide_all if own is None else partial(decide_with, own_step)
        self.world = GridWorld(scenario, layout)
        self.mem = run_memory(scenario, scenario.agents)
        self.cparams = run_params(scenario)
        self.tick = 0
        self.wall_seconds = 0.0

    def step(self, n: int = 1, until: str = "foraged", tap=None) -> int:
        """Run up to n ticks (fewer if `until` is reached); return ticks run.
        A `tap` (swarm.recording.grid.EngineTap) receives every tick's record."""
        w = self.world
        started = time.perf_counter()
        try:
            ran = self._step_physical(n, until, tap) if w.bodies.physical else self._step_ideal(n, until, tap)
        except Exception as exc:  # a user's step that does not compile, raises, or answers what the world refuses
            if self.own is None:
                raise
            raise RunError(compile_line(self.scenario.controller, exc)) from None
        elapsed = time.perf_counter() - started
        self.wall_seconds += elapsed
        if tap is not None and not w.bodies.physical:
            tap.take(self.tick, int(ran), elapsed)
        self.tick += int(ran)
        return int(ran)

    def _step_ideal(self, n: int, until: str, tap) -> int:
        """The compiled loop runs the ticks, the recording's buffers filled in it."""
        w = self.world
        buffers = tap.buffers(n) if tap is not None else _NO_RECORDING
        return self._run_ticks(
            self.kind, w.layers, w.pher, w.pher_scratch, w.base[0], w.base[1], w.pos, w.payload, w.blocked,
            self.mem, w.acts, self.cparams, w.wparams, w.counters, w.pheromone_on, np.int64(self.scenario.seed),
            self.tick, n, UNTIL[until], w.total, w.reachable, tap is not None, *buffers,
        )  # fmt: skip

    def _step_physical(self, n: int, until: str, tap) -> int:
        """Tick by tick: the bodies' simulation (pymunk) sits between deciding and the grid rules."""
        w = self.world
        pi, pf = np.empty(PERC_LEN, np.int64), np.empty(PERC_F_LEN, np.float64)
        seed = np.int64(self.scenario.seed)
        for t in range(n):
            started = time.perf_counter()
            self._decide(self.kind, w.layers, w.pher, w.pheromone_on, w.base[0], w.base[1], w.pos, w.payload, w.blocked,
                       self.mem, w.acts, self.cparams, seed, self.tick + t, pi, pf)  # fmt: skip
            w.resolve(self.tick + t)
            if tap is not None:
                tap.recorder.capture(self.tick + t, tick_ms=(time.perf_counter() - started) * 1000)
            if self.done(until):
                return t + 1
        return n

    def done(self, until: str = "foraged") -> bool:
        w = self.world
        return bool(is_done(UNTIL[until], w.counters, w.total, w.reachable))

    def run(
        self,
        until: str = "foraged",
        max_iterations: int = DEFAULT_MAX_ITERATIONS,
        progress: bool = False,
        chunk: int = 5000,
        recorder=None,
    ) -> RunResult:
        """Run to `until` (or max_iterations).  With a `recorder`
        (swarm.recording.grid.Recorder) every tick goes into the recording."""
        if until not in UNTIL:
            raise ValueError(f"unknown --until {until!r}: choose foraged, converged or both")
        check_until(self.scenario, until)
        bar = None
        if progress:
            from tqdm import tqdm

            bar = tqdm(total=self.world.total, unit="unit", desc="delivered", leave=False)
        shown = 0.0
        tap = None
        if recorder is not None:
            from swarm.recording.grid import EngineTap

            tap = EngineTap(recorder)
            chunk = min(chunk, tap.block)
        try:
            while not self.done(until) and self.tick < max_iterations:
                self.step(min(chunk, max_iterations - self.tick), until, tap)
                if bar is not None and time.monotonic() - shown > 0.1:
                    shown = time.monotonic()
                    bar.n = self.world.delivered
                    bar.set_postfix(tick=self.tick, explored=int(self.world.counters[C_EXPLORED]))
                    bar.refresh()
        finally:
            if bar is not None:
                bar.close()
        return RunResult(self.summary(until))

    def summary(self, until: str = "foraged") -> dict[str, Any]:
        w = self.world
        s = self.scenario
        steps = self.tick * s.agents
        return {
            "scenario": s.name,
            "controller": s.controller,
            "agents": s.agents,
            "seed": s.seed,
            "until": until,
            "iterations": self.tick,
            "finished": self.done(until),
            "delivered": w.delivered,
            "total": w.total,
            "in_transit": w.in_transit,
            "apf_optimal": w.apf_optimal(),
            "optimal_cells": int(w.counters[C_OPTIMAL]),
            "explored_cells": int(w.counters[C_EXPLORED]),
            "reachable_cells": w.reachable,
            "rejected_moves": int(w.counters[C_REJECTED]),
            "grid": list(w.layout.shape),
            "wall_seconds": round(self.wall_seconds, 4),
            "agent_steps_per_second": round(steps / self.wall_seconds) if self.wall_seconds else None,
            **w.bodies.summary(s.agents),
        }


def warm_up(scenario: Scenario, engine: bool = False) -> None:
    """Compile, or load from the cache, what a grid run needs (world_server.WORLD_KINDS): the
    controllers' step, the world's tick kernels, with `engine` this engine's loop."""
    from agents.controllers.grid.envelope import warm_up as warm_up_controllers

    warm_up_controllers()
    scenario = scenario.with_overrides(agents=2)
    GridWorld(scenario).warm_up()
    if engine:
        Engine(scenario).step(2)
