"""The grid's world kind: what binds world_server.server.WorldServer to the grid.

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
)
from world_server.grid.face.own import run_memory, run_params
from world_server.grid.world import C_EXPLORED, C_OPTIMAL, C_REJECTED, L_MARK, UNTIL, GridWorld, is_done
from world_server.server import ACTIVE, WorldServer


class GridKind:
    """The grid bound to the world process (world_server.server.WorldKind)."""

    family = wire.FAMILY_GRID

    def __init__(self, server: WorldServer):
        self.server = server
        self.scenario = server.scenario
        self.world = GridWorld(self.scenario)
        self.world.warm_up()
        grid_wire.warm_up(self.world)
        self.cparams = run_params(self.scenario)  # a user's controller's table too (face.own)
        n = self.scenario.agents
        self.mark_floor = np.zeros(n, dtype=np.int64)  # the lowest mark each agent may write on its cell this tick
        self.memory = run_memory(self.scenario, n)  # every controller's memory after its last step (exact resume)
        self.refused = np.zeros(len(REFUSALS), dtype=np.int64)  # action rows refused since the last count, by reason
        self.accepted = 0  # action rows accepted this tick
        self.arrived: list[tuple[bytes, str]] = []  # action messages not applied yet: (bytes, process)
        self._laid_out: tuple | None = None  # (the groups, their agents in order, where each group's rows start)
        self.expected = 0  # action messages still to come before the tick applies them
        self._arriving = threading.Lock()  # zenoh's threads add to `arrived` and `expected`; the world takes them
        self.state_file = persist.state_path(server.state_dir, server.keys.run) if server.state_dir else None

    def declare(self, put) -> list:
        """Action messages (`_act_callback`) and the marks key space."""
        s, k = self.server, self.server.keys
        return [s.session.declare_subscriber(k.acts, self._act_callback(put)),
                s.session.declare_queryable(k.marks, s.on_query("marks query", "marks?", put)),
                s.session.declare_subscriber(k.marks, s.on_put("mark", "mark", put))]  # fmt: skip

    def handle(self, event: str, item) -> None:
        if event == "mark":
            self._on_mark(item)
        elif event == "marks?":
            self._on_marks_query(item)

    # ------------------------------------------------------------ persistence

    def resume(self) -> bool:
        """Continue a run persisted under this run id, if there is one."""
        state = persist.load(self.state_file) if self.state_file else None
        if state is None:
            return False
        with persist.resuming(self.state_file):
            self.server.check_same_scenario(state["scenario"], self.state_file)
            w = self.world
            for key in persist.ARRAYS:
                getattr(w, key)[...] = state[key]
            w.bodies.place(state["body_xy"])
            self.server.resume_membership(int(state["tick"]), state["slots"], state["stats"])
            self.memory[...] = state["memory"]
        return True

    def save(self) -> None:
        if self.state_file is None:
            return
        s = self.server
        persist.save(self.state_file, self.world, s.tick, s.slots, s.membership(), self.scenario.describe(),
                     memory=self.memory)  # fmt: skip

    # ------------------------------------------------------------------ joins

    def admit(self, request: dict) -> np.ndarray | str:
        if request.get("controller") != self.scenario.controller:
            return f"this run uses controller {self.scenario.controller!r}, not {request.get('controller')!r}"
        return self.server.free_slots()

    def welcome(self, agent: int, replacing: bool) -> dict:
        """A newcomer in a lost agent's slot starts with a fresh body at the base and a fresh memory."""
        if replacing:
            self.world.new_body(agent)
            self.memory[agent] = run_memory(self.scenario, 1)[0]
        return {"controller": self.scenario.controller, "params": self.cparams.tolist(),
                "memory": self.memory[agent].tolist()}  # fmt: skip

    def start(self, resumed: bool) -> None:
        """Agents that survived the world's restart ran a few ticks past the
        saved one: their controllers go back to the saved memory (on the
        observation key, so it arrives before the first observation)."""
        if not resumed:
            return
        s = self.server
        for group, agents in s.grouped(np.flatnonzero(s.slots == ACTIVE)).items():
            s.hand_back(group, proto.memory_message(agents, self.memory[agents]))

    def remove(self, agent: int) -> None:
        self.world.drop_load(agent)
        self.world.remove_body(agent)

    def close(self) -> None:
        pass

    # ------------------------------------------------------------------ ticks

    def observe(self, tick: int, groups: dict[str, np.ndarray]) -> list[tuple[str, bytes]]:
        """Last tick's actions cleared, every active agent perceived in one compiled pass, in group order,
        and every process's message written in one more (`grid_wire.write_observations`)."""
        w = self.world
        self.accepted = 0
        w.acts[:, A_MOVE] = STAY
        w.acts[:, A_MARK] = MARK_NONE
        w.acts[:, A_TRAIL_OP:A_MODE] = 0  # the mode stays as last reported
        agents, bounds = self._layout(groups)
        ints = np.zeros((len(agents), proto.OBS_INTS), dtype=np.int64)
        pf = np.zeros((len(agents), PERC_F_LEN), dtype=np.float64)
        observe_rows(w.layers, w.pher, w.pheromone_on, w.base[0], w.base[1], w.pos, w.payload, w.blocked, agents,
                     ints, pf, self.server.null)  # fmt: skip
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
        out again only when the groups have (`WorldServer.grouped` keeps the same dict until then)."""
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
        world's thread costs as much as the message's own work).  Only what
        the sender's budget lets in gets there (world_server.gate).
        Then one compiled call reads and applies every plain message where its
        bytes lie (`grid_wire.accept_messages`), and the parser takes the
        rest, counts them and says why it refuses them."""
        arriving, wake, take = self._arriving, ("wake", None), self.server.gate.take

        def on_act(sample) -> None:
            if (got := take("act", sample)) is None:
                return
            with arriving:
                self.arrived.append(got)
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
        s = self.server
        s.bytes_in += int(starts[-1])
        groups = np.array([s.group_index.get(group, -1) for _, group in arrived], np.int64)
        status = np.empty(len(arrived), np.int64)
        first, last = s.window()
        buf = np.frombuffer(b"".join(raw for raw, _ in arrived), np.uint8)
        self.accepted += accept_messages(buf, starts, groups, first, last, s.slots, s.group_ids,
                                         s.mode == "lockstep", s.acted, self.world.acts, self.mark_floor,
                                         self.memory, self.refused, status)  # fmt: skip
        for m in np.flatnonzero(status == proto.NOT_PLAIN).tolist():
            self.accepted += self._parsed_act(*arrived[m])

    def _parsed_act(self, raw: bytes, group: str) -> int:
        msg, s = proto.parse_acts(raw), self.server
        if isinstance(msg, wire.Rejected):
            s.stats.reject(f"act: {msg.reason}")
            return 0
        if not s.current(msg.tick):
            s.stats.late_actions += len(msg.rows)
            s.stats.reject("act: not for this tick", len(msg.rows))
            return 0
        refused = accept_rows(msg.rows, s.slots, s.group_ids, s.group_index.get(group, -1), s.mode == "lockstep",
                              s.acted, self.world.acts, self.mark_floor, self.memory)  # fmt: skip
        self.refused += refused
        return len(msg.rows) - int(refused.sum())

    def _count_refusals(self) -> None:
        """The refused rows since the last count, into the run's rejections (once a tick, not per message)."""
        if self.refused.any():
            for reason, count in zip(REFUSALS, self.refused.tolist(), strict=True):
                if count:
                    self.server.stats.reject(reason, count)
            self.refused[:] = 0

    def _on_mark(self, item: tuple[bytes, str]) -> None:
        """Agents' mark writes ride their action rows: a put on the marks key space is counted and refused."""
        self.server.bytes_in += len(item[0])
        self.server.stats.reject("mark: mark writes go in the action rows (swarm/<run>/act/<group>), not on marks/")

    def _on_marks_query(self, query) -> None:
        marks = self.world.layers[L_MARK]
        grid = np.where(marks == MARK_NONE, -1, marks)
        payload = wire.pack({"type": "marks", "tick": self.server.tick, "height": int(grid.shape[0]),
                              "width": int(grid.shape[1]), "marks": grid.ravel().tolist(),
                              "trails": self.world.trails.ravel().tolist()})  # fmt: skip
        self.server.reply(query, f"{self.server.keys.prefix}/marks/grid", payload)

    def may_all_have_answered(self, agents: np.ndarray) -> bool:
        if self.expected > 0:
            return False  # a process's message is still to come (from then on each is applied as it comes)
        self._apply_arrived()
        return self.accepted >= len(agents)

    def barrier_passed(self) -> None:
        self._apply_arrived()
        self._count_refusals()

    def finish(self) -> None:
        self._apply_arrived()  # what came after the last tick's barrier
        self._count_refusals()

    def resolve(self, tick: int, missed: np.ndarray) -> None:
        self.world.acts[missed, A_MOVE] = STAY
        self.world.acts[missed, A_TRAIL_OP:A_MODE] = 0
        if not self.server.null:
            self.world.resolve(tick)

    def done(self) -> bool:
        w = self.world
        return bool(is_done(UNTIL[self.server.until], w.counters, w.total, w.reachable))

    # ---------------------------------------------------------------- summary

    def progress(self) -> dict:
        return {"delivered": self.world.delivered, "total": self.world.total}

    def summary(self) -> dict:
        w, s = self.world, self.scenario
        return {
            "scenario": s.name, "controller": s.controller, "agents": s.agents, "seed": s.seed,
            "until": self.server.until, "iterations": self.server.tick, "finished": self.done(),
            "delivered": w.delivered, "total": w.total, "in_transit": w.in_transit, "apf_optimal": w.apf_optimal(),
            "optimal_cells": int(w.counters[C_OPTIMAL]), "explored_cells": int(w.counters[C_EXPLORED]),
            "reachable_cells": w.reachable, "rejected_moves": int(w.counters[C_REJECTED]),
            "grid": list(w.layout.shape), **w.bodies.summary(s.agents),
        }  # fmt: skip
