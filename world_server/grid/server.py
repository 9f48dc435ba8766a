"""The grid's world process: world_server.server bound to the grid.

The grid's shared environment is the marks key space: any client can `get
swarm/<run>/marks/**`.  Agents' UPDATE-VALUE writes ride their action rows
(the row's mark, checked against the rule on the agent's cell, applied with
the tick and merged by min, as in-process): one message per agent process
and tick each way.  A put on `marks/<group>` is counted and refused.
A lost agent's body leaves the grid, its cargo dropped on its cell as
resource (on the base: delivered), so the others can still finish the run;
a new agent taking the slot over starts with a fresh body at the base.
"""

from __future__ import annotations

import threading

import numpy as np

from swarm.core import wire
from world_server import persist
from world_server.grid import accept as grid_wire
from world_server.grid.accept import (
    OBS_OVERHEAD,
    REFUSALS,
    accept_messages,
    accept_rows,
    mark_floors,
    observe_rows,
    write_observations,
)
from world_server.grid.face import wire as proto
from world_server.grid.face.layout import (
    A_MARK,
    A_MODE,
    A_MOVE,
    A_TRAIL_OP,
    MARK_NONE,
    PERC_F_LEN,
    STAY,
    controller_params,
    new_memory,
)
from world_server.grid.world import C_EXPLORED, C_OPTIMAL, C_REJECTED, L_MARK, UNTIL, GridWorld, is_done
from world_server.server import ACTIVE, JOINING, WorldServer


class GridServer(WorldServer):
    family = wire.FAMILY_GRID

    def _make_world(self) -> None:
        self.world = GridWorld(self.scenario)
        self.world.warm_up()
        grid_wire.warm_up(self.world)
        self.cparams = controller_params(self.scenario)
        n = self.scenario.agents
        self.mark_floor = np.zeros(n, dtype=np.int64)  # the lowest mark each agent may write on its cell this tick
        self.memory = new_memory(n)  # every controller's memory after its last step (saved: exact resume)
        self.refused = np.zeros(len(REFUSALS), dtype=np.int64)  # action rows refused since the last count, by reason
        self.accepted = 0  # action rows accepted this tick
        self.arrived: list[tuple[bytes, str]] = []  # action messages not applied yet: (bytes, process)
        self._laid_out: tuple | None = None  # (the groups, their agents in order, where each group's rows start)
        self.expected = 0  # action messages still to come before the tick applies them
        self._arriving = threading.Lock()  # zenoh's threads add to `arrived` and `expected`; the world takes them
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
        self._check_same_scenario(state["scenario"])
        w = self.world
        for key in persist.ARRAYS:
            getattr(w, key)[...] = state[key]
        w.bodies.place(state["body_xy"])
        self.tick = int(state["tick"])
        slots = state["slots"]
        # Agents that were in the run come back when their liveliness token reappears.
        self.slots[:] = np.where((slots == ACTIVE) | (slots == JOINING), JOINING, slots)
        self.returning[:] = self.slots == JOINING
        self.memory[...] = state["memory"]
        self.stats.joins = int(state["stats"].get("joins", 0))
        self.stats.agents_lost = int(state["stats"].get("agents_lost", 0))
        self.stats.rejected = dict(state["stats"].get("rejected", {}))
        for a, g in state["stats"].get("groups", {}).items():
            self._assign_group(int(a), g)
        return True

    def save_state(self) -> None:
        if self.state_file is None:
            return
        stats = {"joins": self.stats.joins, "agents_lost": self.stats.agents_lost, "rejected": self.stats.rejected,
                 "groups": {str(a): g for a, g in self.group_of.items()}}  # fmt: skip
        persist.save(self.state_file, self.world, self.tick, self.slots, stats, self.scenario.describe(),
                     memory=self.memory)  # fmt: skip

    # ------------------------------------------------------------------ joins

    def _join_refusal(self, request: dict) -> str | None:
        if request.get("controller") != self.scenario.controller:
            return f"this run uses controller {self.scenario.controller!r}, not {request.get('controller')!r}"
        return None

    def _welcome(self, agent: int) -> dict:
        return {"controller": self.scenario.controller, "params": self.cparams.tolist(),
                "memory": self.memory[agent].tolist()}  # fmt: skip

    def _reuse(self, agent: int) -> None:
        self.world.new_body(agent)
        self.memory[agent] = new_memory(1)[0]

    def _hand_back(self) -> None:
        """Agents that survived the world's restart ran a few ticks past the
        saved one: their controllers go back to the saved memory (on the
        observation key, so it arrives before the first observation)."""
        for group, agents in self._groups(np.flatnonzero(self.slots == ACTIVE)).items():
            self._publisher(group).put(proto.memory_message(agents, self.memory[agents]))

    def _remove(self, agent: int) -> None:
        self.world.drop_load(agent)
        self.world.remove_body(agent)

    # ------------------------------------------------------------------ ticks

    def _begin_tick(self) -> None:
        w = self.world
        self.accepted = 0
        w.acts[:, A_MOVE] = STAY
        w.acts[:, A_MARK] = MARK_NONE
        w.acts[:, A_TRAIL_OP:A_MODE] = 0  # the mode stays as last reported

    def _observations(self, tick: int, groups: dict[str, np.ndarray]):
        """Every active agent perceived in one compiled pass, in group order, and
        every process's message written in one more (`grid_wire.write_observations`)."""
        w = self.world
        agents, bounds = self._layout(groups)
        ints = np.zeros((len(agents), proto.OBS_INTS), dtype=np.int64)
        pf = np.zeros((len(agents), PERC_F_LEN), dtype=np.float64)
        observe_rows(w.layers, w.pher, w.pheromone_on, w.base[0], w.base[1], w.pos, w.payload, w.blocked, agents,
                     ints, pf, self.null)  # fmt: skip
        mark_floors(ints, agents, self.mark_floor)  # marks change only when the tick resolves
        out = np.empty(len(groups) * OBS_OVERHEAD + ints.nbytes + pf.nbytes, np.uint8)
        offsets = np.empty(len(groups) + 1, np.int64)
        data = out[: write_observations(tick, ints, pf, bounds, out, offsets)].tobytes()
        with self._arriving:
            self.expected = len(groups)
        at = offsets.tolist()
        return [(group, data[at[g] : at[g + 1]]) for g, group in enumerate(groups)]

    def _layout(self, groups: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """The agents in group order and where each group's rows start: worked
        out again only when the groups have (`_groups` keeps the same dict until then)."""
        if self._laid_out is None or self._laid_out[0] is not groups:
            agents = np.concatenate(list(groups.values())) if groups else np.zeros(0, np.int64)
            bounds = np.zeros(len(groups) + 1, np.int64)
            np.cumsum([len(members) for members in groups.values()], out=bounds[1:])
            self._laid_out = (groups, agents, bounds)
        return self._laid_out[1], self._laid_out[2]

    def _act_callback(self, put):
        """An action message waits, as it came, in `arrived` until the tick's
        messages are all in (or the barrier's end needs them applied): zenoh's
        thread adds it there and wakes the world only for the tick's last
        message, not for each of a hundred (on two cores each wake of the
        world's thread costs as much as the message's own work).
        Then one compiled call reads and applies every plain message where its
        bytes lie (`grid_wire.accept_messages`), and the parser takes the
        rest, counts them and says why it refuses them."""
        arriving, wake = self._arriving, ("wake", None)

        def on_act(sample) -> None:
            raw = sample.payload.to_bytes()
            group = str(sample.key_expr).rsplit("/", 1)[1]
            with arriving:
                self.arrived.append((raw, group))
                self.expected -= 1
                last = self.expected <= 0
            if last:
                put(wake)

        return on_act

    def _apply_arrived(self) -> None:
        with self._arriving:
            arrived, self.arrived = self.arrived, []
        if not arrived:
            return
        starts = np.zeros(len(arrived) + 1, np.int64)
        np.cumsum(np.fromiter((len(raw) for raw, _ in arrived), np.int64, len(arrived)), out=starts[1:])
        self.bytes_in += int(starts[-1])
        groups = np.array([self.group_index.get(group, -1) for _, group in arrived], np.int64)
        status = np.empty(len(arrived), np.int64)
        first, last = self._window()
        buf = np.frombuffer(b"".join(raw for raw, _ in arrived), np.uint8)
        self.accepted += accept_messages(buf, starts, groups, first, last, self.slots, self.group_ids,
                                         self.mode == "lockstep", self.acted, self.world.acts, self.mark_floor,
                                         self.memory, self.refused, status)  # fmt: skip
        for m in np.flatnonzero(status == proto.NOT_PLAIN).tolist():
            self.accepted += self._parsed_act(*arrived[m])

    def _parsed_act(self, raw: bytes, group: str) -> int:
        msg = proto.parse_acts(raw)
        if isinstance(msg, wire.Rejected):
            self.stats.reject(f"act: {msg.reason}")
            return 0
        if not self._current(msg.tick):
            self.stats.late_actions += len(msg.rows)
            self.stats.reject("act: not for this tick", len(msg.rows))
            return 0
        refused = accept_rows(msg.rows, self.slots, self.group_ids, self.group_index.get(group, -1),
                              self.mode == "lockstep", self.acted, self.world.acts, self.mark_floor,
                              self.memory)  # fmt: skip
        self.refused += refused
        return len(msg.rows) - int(refused.sum())

    def _count_refusals(self) -> None:
        """The refused rows since the last count, into the run's rejections (once a tick, not per message)."""
        if self.refused.any():
            for reason, count in zip(REFUSALS, self.refused.tolist(), strict=True):
                if count:
                    self.stats.reject(reason, count)
            self.refused[:] = 0

    def _on_mark(self, sample) -> None:
        """Agents' mark writes ride their action rows: a put on the marks key space is counted and refused."""
        self.bytes_in += len(sample.payload)
        self.stats.reject("mark: mark writes go in the action rows (swarm/<run>/act/<group>), not on marks/")

    def _on_marks_query(self, query) -> None:
        marks = self.world.layers[L_MARK]
        grid = np.where(marks == MARK_NONE, -1, marks)
        payload = wire.pack({"type": "marks", "tick": self.tick, "height": int(grid.shape[0]),
                              "width": int(grid.shape[1]), "marks": grid.ravel().tolist(),
                              "trails": self.world.trails.ravel().tolist()})  # fmt: skip
        self._reply(query, f"{self.keys.prefix}/marks/grid", payload)

    def may_all_have_answered(self, agents: np.ndarray) -> bool:
        if self.expected > 0:
            return False  # a process's message is still to come (from then on each is applied as it comes)
        self._apply_arrived()
        return self.accepted >= len(agents)

    def barrier_passed(self) -> None:
        self._apply_arrived()
        self._count_refusals()

    def _finish(self) -> None:
        self._apply_arrived()  # what came after the last tick's barrier
        self._count_refusals()

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
