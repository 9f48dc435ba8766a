"""The world process: the authoritative grid served over zenoh, ticked in lock-step.

Every zenoh callback only enqueues; one thread (`run`) owns the world.  A tick:
publish every active agent's observation, gather their actions and mark writes
until all have answered or the deadline passes (a late agent does nothing that
tick; after `max_misses` misses in a row, or when its liveliness token goes,
it is lost and its slot is free for a new agent), then resolve the tick with
the same `GridWorld.resolve` as the in-process engine.  A lost agent's body
leaves the grid, its cargo dropped on its cell as resource (on the base: delivered), so the
others can still finish the run; a new agent taking the slot over starts with
a fresh body at the base.
"""

from __future__ import annotations

import functools
import json
import queue
import sys
import time
import uuid
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import zenoh

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
from swarm.bus import open_client, open_router
from swarm.engine import UNTIL, is_done
from swarm.scenario import Scenario
from world_server import persist
from world_server.grid import C_EXPLORED, C_OPTIMAL, C_REJECTED, L_MARK, L_OBST, GridWorld, write_mark

# JOINING: welcomed, but its observation subscriber may not be routed yet; it is
# ACTIVE once its liveliness token arrives (declared after the subscriber).
FREE, JOINING, ACTIVE, LOST = 0, 1, 2, 3


@dataclass
class Stats:
    rejected: dict[str, int] = field(default_factory=dict)
    agents_lost: int = 0
    joins: int = 0
    late_actions: int = 0
    missed_ticks: int = 0

    def reject(self, reason: str) -> None:
        self.rejected[reason] = self.rejected.get(reason, 0) + 1

    @property
    def rejected_total(self) -> int:
        return sum(self.rejected.values())


class WorldServer:
    def __init__(
        self, scenario: Scenario, run_id: str, listen: str | None = None, connect: str | None = None,
        deadline: float = 2.0, max_misses: int = 3, start_with: int | None = None, start_timeout: float = 60.0,
        until: str = "foraged", max_iterations: int = 1_000_000, null: bool = False,
        state_dir: str | None = None, persist_every: int = 50, resume_timeout: float = 30.0,
        mode: str = "lockstep", rate: float = 20.0, record: str | None = None, viewer: str | None = None,
    ):  # fmt: skip
        if mode not in ("lockstep", "realtime"):
            raise ValueError(f"unknown mode {mode!r}: lockstep or realtime")
        if not rate > 0:
            raise ValueError("the real-time rate must be positive")
        self.mode = mode
        self.period = 1.0 / rate
        self.scenario = scenario
        self.keys = proto.Keys(run_id)
        self.world = GridWorld(scenario)
        self.world.warm_up()
        self.cparams = controller_params(scenario)
        self.deadline = deadline
        self.max_misses = max_misses
        # Ticking starts once `start_with` agents are active; more may join later, up to scenario.agents.
        self.start_with = scenario.agents if start_with is None else min(start_with, scenario.agents)
        self.final: dict | None = None  # the summary, frozen when the run has ended
        self.agents_peak = 0  # most agents active at the end of one tick
        self.start_timeout = start_timeout
        self.until = until
        self.max_iterations = max_iterations
        self.null = null  # benchmark floor: messaging only, no perception and no world rules
        self.tick_seconds: list[float] = []
        self.bytes_out = 0
        self.bytes_in = 0
        self.agent_steps = 0  # actions received in time, over the run
        self.slots = np.full(scenario.agents, FREE, dtype=np.int64)
        self.misses = np.zeros(scenario.agents, dtype=np.int64)
        self.acted = np.zeros(scenario.agents, dtype=bool)  # action received this tick
        self.mark_due = np.zeros(scenario.agents, dtype=bool)  # its action announced a mark write
        self.mark_got = np.zeros(scenario.agents, dtype=bool)  # that mark write arrived
        self.nonces: dict[str, int] = {}
        self.group_of: dict[int, str] = {}  # agent -> its agent process (message group)
        self.stats = Stats()
        self.tick = 0
        self.events: queue.Queue = queue.Queue()
        self.started = 0.0
        self.persist_every = persist_every
        self.resume_timeout = resume_timeout
        self.state_file = persist.state_path(state_dir, run_id) if state_dir else None
        self.resumed = self._resume()
        self.recording_path: str | None = None
        self.recorder = None if null or not record else self._recorder(record, viewer)
        self.session = open_client(connect) if connect else open_router(listen or "tcp/127.0.0.1:7447")
        put = self.events.put
        k = self.keys
        self._decls = [
            self.session.declare_queryable(k.join, lambda q: put(("join", q))),
            self.session.declare_queryable(k.info, lambda q: put(("info", q))),
            self.session.declare_queryable(k.marks, lambda q: put(("marks?", q))),
            self.session.declare_subscriber(k.acts, lambda s: put(("act", s))),
            self.session.declare_subscriber(k.marks, lambda s: put(("mark", s))),
            # history: tokens declared before this subscriber (agents back before a restarted world) count too
            self.session.liveliness().declare_subscriber(k.alive_all, lambda s: put(("alive", s)), history=True),
        ]

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

    def _recorder(self, record: str, viewer: str | None):
        """A resumed run records into a new file from its resume tick: the
        first file stays as it was (rerun merges files of one recording id).
        `record` may name a folder (ending in /): the file is then
        <run-id>-<UTC time>.rrd in it, as containers write to a mounted folder."""
        from swarm.recording import Recorder, run_meta

        path = Path(record)
        if record.endswith("/") or path.is_dir():  # a folder: one new file per run, never overwritten
            path = path / f"{self.keys.run}-{time.strftime('%Y%m%d-%H%M%S', time.gmtime())}.rrd"
        elif self.resumed and path.exists():
            path = path.with_name(f"{path.stem}.from-{self.tick}{path.suffix}")
        meta = run_meta(self.scenario, self.world, self.keys.run, self.until, self.mode)
        meta["resumed_at"] = self.tick if self.resumed else None
        self.recording_path = str(path)
        return Recorder(path, self.world, meta, viewer=viewer)

    def save_state(self) -> None:
        if self.state_file is None:
            return
        stats = {"joins": self.stats.joins, "agents_lost": self.stats.agents_lost, "rejected": self.stats.rejected,
                 "groups": {str(a): g for a, g in self.group_of.items()}}  # fmt: skip
        persist.save(self.state_file, self.world, self.tick, self.slots, stats, self.scenario.describe())

    # ---------------------------------------------------------------- messages

    def _handle(self, kind: str, item) -> None:
        if kind == "act":
            self._on_act(item)
        elif kind == "mark":
            self._on_mark(item)
        elif kind == "join":
            self._on_join(item)
        elif kind == "info":
            self._reply(item, self.keys.info, proto.pack(self.info()))
        elif kind == "marks?":
            self._on_marks_query(item)
        elif kind == "alive":
            self._on_alive(item)

    def _reply(self, query, key: str, payload: bytes) -> None:
        try:
            query.reply(key, payload)
        finally:
            query.drop()

    def _on_join(self, query) -> None:
        raw = query.payload.to_bytes() if query.payload is not None else b""
        request = proto.parse_join(raw)
        if isinstance(request, proto.Rejected):
            self.stats.reject(f"join: {request.reason}")
            self._reply(query, self.keys.join, proto.refuse_reply(request.reason))
            return
        if request.get("controller") != self.scenario.controller:
            reason = f"this run uses controller {self.scenario.controller!r}, not {request.get('controller')!r}"
            self._reply(query, self.keys.join, proto.refuse_reply(reason))
            return
        if self.final is not None:
            self._reply(query, self.keys.join, proto.refuse_reply(proto.ENDED))
            return
        nonce = request["nonce"]
        agent = self.nonces.get(nonce)  # a retried join gets the same id
        if agent is None:
            free = np.flatnonzero((self.slots == FREE) | (self.slots == LOST))
            if len(free) == 0:
                self._reply(query, self.keys.join, proto.refuse_reply("the swarm is full"))
                return
            agent = int(free[0])
            if self.slots[agent] == LOST:
                self.world.new_body(agent)
            self.nonces[nonce] = agent
            self.group_of[agent] = request["group"]
            self.slots[agent] = JOINING
            self.misses[agent] = 0
            self.stats.joins += 1
        info = {"run": self.keys.run, "seed": self.scenario.seed, "controller": self.scenario.controller,
                "params": self.cparams.tolist(), "tick": self.tick}  # fmt: skip
        self._reply(query, self.keys.join, proto.join_reply(agent, nonce, info))

    def _on_alive(self, sample) -> None:
        agent = self._sender(sample)
        if agent is None or not 0 <= agent < len(self.slots):
            return
        if sample.kind == zenoh.SampleKind.PUT and self.slots[agent] == JOINING:
            self.slots[agent] = ACTIVE
        elif sample.kind == zenoh.SampleKind.DELETE and self.slots[agent] in (JOINING, ACTIVE):
            self._lose(agent)

    def _lose(self, agent: int) -> None:
        self.slots[agent] = LOST
        self.stats.agents_lost += 1
        if not self.done():  # after the run, agents leaving do not change the final world
            self.world.drop_load(agent)
            self.world.remove_body(agent)
        for nonce, a in list(self.nonces.items()):
            if a == agent:
                del self.nonces[nonce]

    def _sender(self, sample) -> int | None:
        try:
            return int(str(sample.key_expr).rsplit("/", 1)[1])
        except ValueError:
            return None

    def _receive(self, sample, parse, what: str):
        """(message, sending group), or None after counting a rejection."""
        raw = sample.payload.to_bytes()
        self.bytes_in += len(raw)
        msg = parse(raw)
        if isinstance(msg, proto.Rejected):
            self.stats.reject(f"{what}: {msg.reason}")
            return None
        return msg, str(sample.key_expr).rsplit("/", 1)[1]

    def _on_act(self, sample) -> None:
        received = self._receive(sample, proto.parse_acts, "act")
        if received is None:
            return
        msg, group = received
        for a, act, marked in zip(msg.agents.tolist(), msg.acts, msg.marked.tolist(), strict=True):
            if not (0 <= a < len(self.slots)) or self.slots[a] != ACTIVE:
                self.stats.reject("act: unknown agent")
            elif self.group_of.get(a) != group:
                self.stats.reject("act: names an agent of another process")
            elif not self._current(msg.tick):
                self.stats.late_actions += 1
                self.stats.reject("act: not for this tick")
            elif self.acted[a] and self.mode == "lockstep":  # in real time the latest action wins
                self.stats.reject("act: second action in one tick")
            elif not _valid_action(act):
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

    def _current(self, tick: int) -> bool:
        """Lock-step: only this tick.  Real time: this tick or the two before
        (an agent may answer a slightly old observation)."""
        if self.mode == "lockstep":
            return tick == self.tick
        return self.tick - 2 <= tick <= self.tick

    def _on_marks_query(self, query) -> None:
        marks = self.world.layers[L_MARK]
        grid = np.where(marks == MARK_NONE, -1, marks)
        payload = proto.pack({"type": "marks", "tick": self.tick, "height": int(grid.shape[0]),
                              "width": int(grid.shape[1]), "marks": grid.ravel().tolist(),
                              "trails": self.world.trails.ravel().tolist()})  # fmt: skip
        self._reply(query, f"{self.keys.prefix}/marks/grid", payload)

    def _drain(self, timeout: float) -> bool:
        """Handle queued events; wait up to `timeout` for the first one."""
        try:
            kind, item = self.events.get(timeout=timeout)
        except queue.Empty:
            return False
        self._handle(kind, item)
        while True:
            try:
                kind, item = self.events.get_nowait()
            except queue.Empty:
                return True
            self._handle(kind, item)

    # ------------------------------------------------------------------ ticks

    def wait_for_agents(self) -> None:
        if self.resumed:
            deadline = time.monotonic() + self.resume_timeout
            while (self.slots == JOINING).any() and time.monotonic() < deadline:
                self._drain(0.05)
            for agent in np.flatnonzero(self.slots == JOINING):
                self._lose(int(agent))  # did not come back
            return
        deadline = time.monotonic() + self.start_timeout
        while int((self.slots == ACTIVE).sum()) < self.start_with:
            if time.monotonic() > deadline:
                raise TimeoutError(f"only {int((self.slots == ACTIVE).sum())} of {self.start_with} agents joined")
            self._drain(0.05)

    def _wait_for_any_agent(self) -> None:
        deadline = time.monotonic() + self.start_timeout
        while not (self.slots == ACTIVE).any():
            if time.monotonic() > deadline:
                raise TimeoutError(f"every agent is gone and none joined for {self.start_timeout:g} s; "
                                   "start agents with `swarm agent --run-id ...`")  # fmt: skip
            self._drain(0.05)

    def step(self) -> None:
        started = time.perf_counter()
        w = self.world
        tick = self.tick
        active = np.flatnonzero(self.slots == ACTIVE)
        self.acted[:] = False
        self.mark_due[:] = False
        self.mark_got[:] = False
        w.acts[:, A_MOVE] = STAY
        w.acts[:, A_MARK] = MARK_NONE
        w.acts[:, A_TRAIL_OP:A_MODE] = 0  # the mode stays as last reported
        for group, agents in self._groups(active).items():
            pi = np.zeros((len(agents), PERC_LEN), dtype=np.int64)
            pf = np.zeros((len(agents), PERC_F_LEN), dtype=np.float64)
            if not self.null:
                for i, a in enumerate(agents):
                    w.perceive(int(a), pi[i], pf[i])
            cells = w.pos[agents, 0] * w.layers.shape[2] + w.pos[agents, 1]
            payload = proto.observations(tick, agents, cells, pi, pf)
            self.bytes_out += len(payload)
            self.session.put(self.keys.obs(group), payload)
        if self.mode == "lockstep":  # a barrier: until all have answered or the deadline
            deadline = time.monotonic() + self.deadline
            while not self.answered(active).all():
                left = deadline - time.monotonic()
                if left <= 0:
                    break
                self._drain(left)
        else:  # real time: the tick lasts one period, whoever has answered
            deadline = started + self.period
            while (left := deadline - time.monotonic()) > 0:
                self._drain(left)
        answered = self.answered(active)
        self.agent_steps += int(answered.sum())
        for a, ok in zip(active, answered, strict=True):
            if ok:
                self.misses[a] = 0
            elif self.slots[a] == ACTIVE:
                self.misses[a] += 1
                self.stats.missed_ticks += 1
                w.acts[a, A_MOVE] = STAY
                w.acts[a, A_TRAIL_OP:A_MODE] = 0
                if self.misses[a] >= self.max_misses:
                    self._lose(int(a))
        if not self.null:
            w.resolve(tick)
        self.tick += 1
        if self.persist_every and self.tick % self.persist_every == 0:
            self.save_state()
        self.tick_seconds.append(time.perf_counter() - started)
        present = self.slots == ACTIVE
        self.agents_peak = max(self.agents_peak, int(present.sum()))
        if self.recorder is not None:
            self.recorder.capture(tick, present=present, tick_ms=self.tick_seconds[-1] * 1000,
                                  rejected=self.stats.rejected_total)  # fmt: skip
        self.session.put(self.keys.state, proto.pack({"type": "state", **self.progress()}))

    def _groups(self, agents: np.ndarray) -> dict[str, np.ndarray]:
        groups: dict[str, list[int]] = {}
        for a in agents.tolist():
            groups.setdefault(self.group_of[a], []).append(a)
        return {g: np.array(members, dtype=np.int64) for g, members in groups.items()}

    def answered(self, agents: np.ndarray) -> np.ndarray:
        if self.mode == "realtime":
            return self.acted[agents]
        return self.acted[agents] & (~self.mark_due[agents] | self.mark_got[agents])

    def done(self) -> bool:
        w = self.world
        return bool(is_done(UNTIL[self.until], w.counters, w.total, w.reachable))

    def run(self) -> dict:
        if not (self.resumed and self.done()):  # a finished run resumed has nothing left to do
            self.wait_for_agents()
        self.started = time.monotonic()
        while not self.done() and self.tick < self.max_iterations:
            if not (self.slots == ACTIVE).any():
                self._wait_for_any_agent()  # a world with nobody in it does not tick on alone
            self.step()
        self._drain(0.0)
        self.save_state()
        self.final = summary = self.summary()
        self._close_recording(summary)
        return summary

    def _close_recording(self, summary: dict) -> None:
        if self.recorder is not None:
            self.recorder.close(summary)
            self.recorder = None

    def linger(self, until) -> None:
        """Keep serving the key space (marks, info) after the run until
        `until()` is true: clients can still read the final marking environment."""
        while not until():
            self._drain(0.1)

    def info(self) -> dict:
        """What `swarm status`, `swarm monitor` and agents checking their
        membership read: the summary so far (final once ended), the ids of the
        agents in the run, and whether it has ended."""
        members = np.flatnonzero((self.slots == ACTIVE) | (self.slots == JOINING)).tolist()
        summary = self.final if self.final is not None else self.summary()
        return {"type": "info", **summary, "members": members, "ended": self.final is not None,
                "agents_alive": int((self.slots == ACTIVE).sum()), "start_with": self.start_with,
                "tick": self.tick}  # fmt: skip

    def progress(self) -> dict:
        w = self.world
        elapsed = time.monotonic() - self.started if self.started else 0.0
        return {"tick": self.tick, "delivered": w.delivered, "total": w.total,
                "agents_alive": int((self.slots == ACTIVE).sum()),
                "ticks_per_second": round(self.tick / elapsed, 2) if elapsed > 0 else 0.0}  # fmt: skip

    def summary(self) -> dict:
        w, s = self.world, self.scenario
        elapsed = time.monotonic() - self.started if self.started else 0.0
        return {
            "scenario": s.name, "controller": s.controller, "agents": s.agents, "seed": s.seed,
            "until": self.until, "iterations": self.tick, "finished": self.done(), "delivered": w.delivered,
            "total": w.total, "in_transit": w.in_transit, "apf_optimal": w.apf_optimal(),
            "optimal_cells": int(w.counters[C_OPTIMAL]), "explored_cells": int(w.counters[C_EXPLORED]),
            "reachable_cells": w.reachable, "rejected_moves": int(w.counters[C_REJECTED]),
            "grid": list(w.layout.shape), "run_id": self.keys.run, "mode": self.mode,
            "rejected_messages": self.stats.rejected_total, "rejected_by_reason": dict(self.stats.rejected),
            "agents_lost": self.stats.agents_lost, "joins": self.stats.joins, "missed_ticks": self.stats.missed_ticks,
            "agents_peak": self.agents_peak,
            "ticks_per_second": round(self.tick / elapsed, 2) if elapsed > 0 else 0.0,
            "wall_seconds": round(elapsed, 3), **w.bodies.summary(s.agents), **self._latency(),
            "recording": self.recording_path,
        }  # fmt: skip

    def _latency(self) -> dict:
        ticks = np.array(self.tick_seconds) * 1000 if self.tick_seconds else np.zeros(1)
        return {"tick_ms_p50": round(float(np.percentile(ticks, 50)), 3),
                "tick_ms_p99": round(float(np.percentile(ticks, 99)), 3), "tick_ms_max": round(float(ticks.max()), 3),
                "payload_bytes_out": self.bytes_out, "payload_bytes_in": self.bytes_in,
                "agent_steps": self.agent_steps}  # fmt: skip

    def stop_agents(self, reason: str) -> None:
        for group in set(self.group_of.values()):
            self.session.put(self.keys.obs(group), proto.stop_message(reason))

    def close(self) -> None:
        if self.recorder is not None:  # an interrupted run still ends its recording
            self._close_recording(self.summary())
        for d in self._decls:
            d.undeclare()
        self.session.close()


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


def new_run_id() -> str:
    return uuid.uuid4().hex[:8]


def serve(scenario: Scenario, run_id: str, summary_file: str | None = None, linger: float = 0.0, quiet: bool = False,
          **kw) -> dict:  # fmt: skip
    server = WorldServer(scenario, run_id, **kw)
    log = (lambda *_: None) if quiet else functools.partial(print, file=sys.stderr, flush=True)
    try:
        log(f"swarm world: run {run_id!r}, {scenario.name} (seed {scenario.seed}, {scenario.controller}): "
            f"{server.start_with} agents start it, up to {scenario.agents} may join")  # fmt: skip
        summary = server.run()
        log(f"swarm world: run {run_id!r} {'finished' if summary['finished'] else 'stopped'} after "
            f"{summary['iterations']} ticks; recording: {summary['recording']}")  # fmt: skip
        if linger > 0:
            log(f"swarm world: serving the final state for {linger:g} s")
        server.stop_agents("finished" if summary["finished"] else "stopped")
        if summary_file:
            with open(summary_file, "w") as f:
                json.dump(summary, f)
        end = time.monotonic() + linger
        server.linger(lambda: time.monotonic() >= end)
    finally:
        server.close()
    return summary
