"""The grid's world process: world_server.server bound to the grid.

The grid's shared environment is the marks key space: agents put their
UPDATE-VALUE writes on `swarm/<run>/marks/<group>` (merged by min, each
checked against the rule), and any client can `get swarm/<run>/marks/**`.
A lost agent's body leaves the grid, its cargo dropped on its cell as
resource (on the base: delivered), so the others can still finish the run;
a new agent taking the slot over starts with a fresh body at the base.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from agents.controllers.dispatch import controller_params
from agents.controllers.layout import (
    A_DEPOSIT,
    A_LOAD,
    A_MARK,
    A_MODE,
    A_MOVE,
    A_TRAIL_ID,
    A_TRAIL_OP,
    A_UNLOAD,
    MARK_NONE,
    N_MODES,
    PERC_F_LEN,
    PERC_LEN,
    STAY,
    TRAIL_ERASE,
)  # fmt: skip
from swarm import protocol as proto
from swarm.engine import UNTIL, is_done
from world_server import persist
from world_server.grid import C_EXPLORED, C_OPTIMAL, C_REJECTED, L_MARK, L_OBST, GridWorld, write_mark
from world_server.server import ACTIVE, JOINING, WorldServer


class GridServer(WorldServer):
    family = proto.FAMILY_GRID

    def _make_world(self) -> None:
        self.world = GridWorld(self.scenario)
        self.world.warm_up()
        self.cparams = controller_params(self.scenario)
        n = self.scenario.agents
        self.mark_due = np.zeros(n, dtype=bool)  # its action announced a mark write
        self.mark_got = np.zeros(n, dtype=bool)  # that mark write arrived
        self.state_file = persist.state_path(self.state_dir, self.keys.run) if self.state_dir else None

    def _declare_shared(self, put) -> list:
        k = self.keys
        return [self.session.declare_queryable(k.marks, lambda q: put(("marks?", q))),
                self.session.declare_subscriber(k.marks, lambda s: put(("mark", s)))]  # fmt: skip

    def _handle_shared(self, kind: str, item) -> None:
        if kind == "mark":
            self._on_mark(item)
        elif kind == "marks?":
            self._on_marks_query(item)

    # ------------------------------------------------------------ persistence

    def _resume(self) -> bool:
        """Continue a run persisted under this run id, if there is one."""
        state = persist.load(self.state_file) if self.state_file else None
        if state is None:
            return False
        if state["scenario"] != self.scenario.describe():
            raise ValueError(f"{self.state_file} holds run {self.keys.run!r} of another scenario; "
                             "use another --run-id or remove the file")  # fmt: skip
        w = self.world
        for key in persist.ARRAYS:
            getattr(w, key)[...] = state[key]
        w.bodies.place(state["body_xy"])
        self.tick = int(state["tick"])
        slots = state["slots"]
        # Agents that were in the run come back when their liveliness token reappears.
        self.slots[:] = np.where((slots == ACTIVE) | (slots == JOINING), JOINING, slots)
        self.stats.joins = int(state["stats"].get("joins", 0))
        self.stats.agents_lost = int(state["stats"].get("agents_lost", 0))
        self.stats.rejected = dict(state["stats"].get("rejected", {}))
        self.group_of = {int(a): g for a, g in state["stats"].get("groups", {}).items()}
        return True

    def _open_recorder(self, path: Path, viewer: str | None):
        from swarm.recording import Recorder, run_meta

        meta = run_meta(self.scenario, self.world, self.keys.run, self.until, self.mode)
        meta["resumed_at"] = self.tick if self.resumed else None
        return Recorder(path, self.world, meta, viewer=viewer)

    def save_state(self) -> None:
        if self.state_file is None:
            return
        stats = {"joins": self.stats.joins, "agents_lost": self.stats.agents_lost, "rejected": self.stats.rejected,
                 "groups": {str(a): g for a, g in self.group_of.items()}}  # fmt: skip
        persist.save(self.state_file, self.world, self.tick, self.slots, stats, self.scenario.describe())

    # ------------------------------------------------------------------ joins

    def _join_refusal(self, request: dict) -> str | None:
        if request.get("controller") != self.scenario.controller:
            return f"this run uses controller {self.scenario.controller!r}, not {request.get('controller')!r}"
        return None

    def _welcome(self, agent: int) -> dict:
        return {"controller": self.scenario.controller, "params": self.cparams.tolist()}

    def _reuse(self, agent: int) -> None:
        self.world.new_body(agent)

    def _remove(self, agent: int) -> None:
        self.world.drop_load(agent)
        self.world.remove_body(agent)

    # ------------------------------------------------------------------ ticks

    def _begin_tick(self) -> None:
        w = self.world
        self.mark_due[:] = False
        self.mark_got[:] = False
        w.acts[:, A_MOVE] = STAY
        w.acts[:, A_MARK] = MARK_NONE
        w.acts[:, A_TRAIL_OP:A_MODE] = 0  # the mode stays as last reported

    def _observe(self, tick: int, agents: np.ndarray) -> bytes:
        w = self.world
        pi = np.zeros((len(agents), PERC_LEN), dtype=np.int64)
        pf = np.zeros((len(agents), PERC_F_LEN), dtype=np.float64)
        if not self.null:
            for i, a in enumerate(agents):
                w.perceive(int(a), pi[i], pf[i])
        cells = w.pos[agents, 0] * w.layers.shape[2] + w.pos[agents, 1]
        return proto.observations(tick, agents, cells, pi, pf)

    def _on_act(self, sample) -> None:
        received = self._receive(sample, proto.parse_acts, "act")
        if received is None:
            return
        msg, group = received
        for a, act, marked in zip(msg.agents.tolist(), msg.acts, msg.marked.tolist(), strict=True):
            if not self._acting(a, group, msg.tick):
                continue
            if not _valid_action(act):
                self.stats.reject("act: out-of-range action")
            else:
                row = self.world.acts[a]
                row[:] = act
                row[A_MARK] = MARK_NONE  # marks travel on the marks key space
                self.acted[a] = True
                self.mark_due[a] = marked

    def _on_mark(self, sample) -> None:
        received = self._receive(sample, proto.parse_marks, "mark")
        if received is None:
            return
        msg, group = received
        w = self.world
        width = w.layers.shape[2]
        for a, cell, value in zip(msg.agents.tolist(), msg.cells.tolist(), msg.values.tolist(), strict=True):
            if not (0 <= a < len(self.slots)) or self.slots[a] != ACTIVE:
                self.stats.reject("mark: unknown agent")
            elif self.group_of.get(a) != group:
                self.stats.reject("mark: names an agent of another process")
            elif not self._current(msg.tick) or (
                self.mode == "lockstep" and (self.mark_got[a] or (self.acted[a] and not self.mark_due[a]))
            ):
                self.stats.reject("mark: not for this tick")
            elif cell != w.pos[a, 0] * width + w.pos[a, 1]:
                self.stats.reject("mark: not the agent's cell")
            elif value < _update_bound(w.layers, int(w.pos[a, 0]), int(w.pos[a, 1])):
                self.stats.reject("mark: lower than UPDATE-VALUE allows")
            else:
                write_mark(w.layers, int(w.pos[a, 0]), int(w.pos[a, 1]), np.int64(value), w.counters)
                self.mark_got[a] = True

    def _on_marks_query(self, query) -> None:
        marks = self.world.layers[L_MARK]
        grid = np.where(marks == MARK_NONE, -1, marks)
        payload = proto.pack({"type": "marks", "tick": self.tick, "height": int(grid.shape[0]),
                              "width": int(grid.shape[1]), "marks": grid.ravel().tolist(),
                              "trails": self.world.trails.ravel().tolist()})  # fmt: skip
        self._reply(query, f"{self.keys.prefix}/marks/grid", payload)

    def answered(self, agents: np.ndarray) -> np.ndarray:
        if self.mode == "realtime":
            return self.acted[agents]
        return self.acted[agents] & (~self.mark_due[agents] | self.mark_got[agents])

    def _missed(self, agent: int) -> None:
        self.world.acts[agent, A_MOVE] = STAY
        self.world.acts[agent, A_TRAIL_OP:A_MODE] = 0

    def _resolve(self, tick: int) -> None:
        self.world.resolve(tick)

    def done(self) -> bool:
        w = self.world
        return bool(is_done(UNTIL[self.until], w.counters, w.total, w.reachable))

    # ---------------------------------------------------------------- summary

    def progress_fields(self) -> dict:
        return {"delivered": self.world.delivered, "total": self.world.total}

    def summary_fields(self) -> dict:
        w, s = self.world, self.scenario
        return {
            "scenario": s.name, "controller": s.controller, "agents": s.agents, "seed": s.seed,
            "until": self.until, "iterations": self.tick, "finished": self.done(), "delivered": w.delivered,
            "total": w.total, "in_transit": w.in_transit, "apf_optimal": w.apf_optimal(),
            "optimal_cells": int(w.counters[C_OPTIMAL]), "explored_cells": int(w.counters[C_EXPLORED]),
            "reachable_cells": w.reachable, "rejected_moves": int(w.counters[C_REJECTED]),
            "grid": list(w.layout.shape), **w.bodies.summary(s.agents),
        }  # fmt: skip


def _valid_action(act: np.ndarray) -> bool:
    return bool(
        0 <= act[A_MOVE] <= STAY and 0 <= act[A_TRAIL_OP] <= TRAIL_ERASE and act[A_TRAIL_ID] >= 0
        and all(act[i] in (0, 1) for i in (A_LOAD, A_UNLOAD, A_DEPOSIT)) and 0 <= act[A_MODE] < N_MODES
    )  # fmt: skip


def _update_bound(layers: np.ndarray, r: int, c: int) -> int:
    """The lowest value UPDATE-VALUE can write on (r, c) now."""
    marks, obst = layers[L_MARK], layers[L_OBST]
    h, w = marks.shape
    best = MARK_NONE
    for dr, dc in ((-1, 0), (1, 0), (0, -1), (0, 1)):
        nr, nc = r + dr, c + dc
        if 0 <= nr < h and 0 <= nc < w and not obst[nr, nc]:
            best = min(best, int(marks[nr, nc]))
    return int(min(marks[r, c], best + 1 if best != MARK_NONE else MARK_NONE))
