"""The world process: an authoritative world served over zenoh, ticked in lock-step.

Every zenoh callback only enqueues, what its sender's budget lets in (world_server.gate: a flood is
counted and dropped there, before it is decoded); one thread (`run`) owns the world.  A tick:
publish every active agent's observation, gather their actions until all have
answered or the deadline passes (a late agent does nothing that tick; after
`max_misses` misses in a row, or when its liveliness token goes, it is lost and
its slot is free for a new agent), then resolve the tick with the same world
code as the in-process engine.

This module is the part every world kind shares: joins, presence, the
lock-step barrier, real time, the state key, info, progress and the summary's
runtime fields.  What a kind perceives, which actions it accepts, how it
resolves a tick, persists and reports, the server asks the world kind it holds
(`WorldKind`: `world_server.grid.server.GridKind`, `world_server.arena.server.ArenaKind`).
"""

from __future__ import annotations

import queue
import time
import uuid
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np
import zenoh

from swarm.core import wire
from swarm.core.bus import LOSSLESS, open_client, open_router
from swarm.core.credentials import Identity
from swarm.core.errors import ScenarioError
from world_server.gate import Gate, allowances

# JOINING: welcomed, but its observation subscriber may not be routed yet; it is
# ACTIVE once its liveliness token arrives (declared after the subscriber).
FREE, JOINING, ACTIVE, LOST = 0, 1, 2, 3
STATE_PERIOD = 0.1  # seconds between progress messages on the state key (at most one per tick)


@dataclass
class Stats:
    rejected: dict[str, int] = field(default_factory=dict)
    agents_lost: int = 0
    joins: int = 0
    late_actions: int = 0
    missed_ticks: int = 0
    clock_slips: int = 0  # real-time ticks that started too late to end on the world's clock

    def reject(self, reason: str, count: int = 1) -> None:
        self.rejected[reason] = self.rejected.get(reason, 0) + count

    @property
    def rejected_total(self) -> int:
        return sum(self.rejected.values())


@dataclass(frozen=True)
class RunnerServices:
    """What the runner that starts a world process lends it: the parts of a run that live above the
    worlds (swarm.world_process.services_for builds them for a scenario's kind)."""

    # (server, path, live viewer or None) -> the recorder of this run, when it is recorded
    open_recorder: Callable[[Any, Path, str | None], Any] | None = None
    # scenario -> what the run asks of its robots, kept above the world (the arena's goals, routes, dwell, L_o)
    goals: Callable[[Any], Any] | None = None


class WorldKind(Protocol):
    """What binds the world process to one world kind.  A kind is made with the server it serves
    (`kind(server)`) and reads the server's slots, counts and session; the server asks it:

    messages      declare, handle
    persistence   resume, save
    membership    admit, welcome, remove
    a run         start, finish, close
    a tick        observe, may_all_have_answered, barrier_passed, resolve
    report        done, progress, summary
    """

    world: Any  # the kind's world (world_server.contract.World): what the recorder and the tests read

    def declare(self, put: Callable[[tuple[str, Any]], None]) -> list:
        """The kind's zenoh declarations: how action messages come in, and its shared key spaces.
        Their events go through `put` as (event, item) and come back to `handle` on the world's thread;
        the server's `on_put` and `on_query` make their callbacks, which let in what the budgets allow."""

    def handle(self, event: str, item: Any) -> None:
        """An event of the kind's declarations: an action message, a shared key space's put or query."""

    def resume(self) -> bool:
        """Continue the run saved under this run id, if there is one (the server's `resume_membership`
        takes the slots and counts): True when it did."""

    def save(self) -> None:
        """Persist the world, for a restarted world process to resume (kinds that can)."""

    def admit(self, request: dict) -> np.ndarray | str:
        """The slots this join request may take, in order (`WorldServer.free_slots`, or those of its
        controller), or why it is refused."""

    def welcome(self, agent: int, replacing: bool) -> dict:
        """What a joining agent is told besides its id (its controller, parameters, memory);
        `replacing`: it takes over a lost agent's slot, and starts afresh."""

    def remove(self, agent: int) -> None:
        """An agent is lost during the run: what becomes of its body."""

    def start(self, resumed: bool) -> None:
        """The agents that start the run have joined; the first tick is next.  A resumed run gives the
        agents that survived the restart their controllers' memory at the saved tick."""

    def finish(self) -> None:
        """After the last tick, before the final save: what the last tick left to pass on."""

    def close(self) -> None:
        """The world process ends: release what the kind holds open."""

    def observe(self, tick: int, groups: dict[str, np.ndarray]) -> list[tuple[str, bytes]]:
        """Begin the tick: (group, observation message) for every agent process, by its active agents."""

    def may_all_have_answered(self, agents: np.ndarray) -> bool:
        """A cheap test before the server's, which the lock-step barrier would otherwise evaluate
        after every message: False while some of `agents` surely still owe their action."""

    def barrier_passed(self) -> None:
        """Every answer of the tick is in, or its time is up: take in what has come."""

    def resolve(self, tick: int, missed: np.ndarray) -> None:
        """Resolve the tick (a null run, messaging only, leaves the world as it is); the agents in
        `missed` did not answer and do nothing."""

    def done(self) -> bool:
        """The run has reached its end."""

    def progress(self) -> dict:
        """The kind's few numbers on the state key, ten times a second: cheap."""

    def summary(self) -> dict:
        """The kind's summary of the run so far (the server adds its runtime's fields)."""


class WorldServer:
    """The runtime around one world; it holds the world kind (`WorldKind`) that binds it to its world."""

    def __init__(
        self, kind: Callable[[WorldServer], WorldKind], scenario, run_id: str, listen: str | None = None,
        connect: str | None = None, identity: Identity | None = None,
        deadline: float = 2.0, max_misses: int = 3, start_with: int | None = None, start_timeout: float = 60.0,
        until: str = "foraged", max_iterations: int = 1_000_000, null: bool = False,
        state_dir: str | None = None, persist_every: int = 50, resume_timeout: float = 30.0,
        mode: str = "lockstep", rate: float = 20.0, record: str | None = None, viewer: str | None = None,
        services: RunnerServices | None = None,
    ):  # fmt: skip
        if mode not in ("lockstep", "realtime"):
            raise ValueError(f"unknown mode {mode!r}: lockstep or realtime")
        if not rate > 0:
            raise ValueError("the real-time rate must be positive")
        self.mode = mode
        self.period = 1.0 / rate
        self.scenario = scenario
        self.keys = wire.Keys(run_id)
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
        self._init_bookkeeping()
        self.persist_every = persist_every
        self.resume_timeout = resume_timeout
        self.state_dir = state_dir
        self.services = services or RunnerServices()
        self.kind = kind(self)
        self.resumed = self.kind.resume()
        self.recording_path: str | None = None
        self.recorder = None if null or not record else self._recorder(record, viewer)
        self._open_session(listen, connect, identity)

    def _init_bookkeeping(self) -> None:
        """Traffic and timing counters, the agent slots and their message groups, and the event queue."""
        self.tick_seconds: list[float] = []
        self.bytes_out = 0
        self.bytes_in = 0
        self.agent_steps = 0  # actions received in time, over the run
        self.slots = np.full(self.scenario.agents, FREE, dtype=np.int64)
        self.misses = np.zeros(self.scenario.agents, dtype=np.int64)
        # A resumed run's agents that have not come back yet: a newcomer takes one over (body and memory).
        self.returning = np.zeros(self.scenario.agents, dtype=bool)
        self.acted = np.zeros(self.scenario.agents, dtype=bool)  # action received this tick
        self.nonces: dict[str, int] = {}
        self.group_of: dict[int, str] = {}  # agent -> its agent process (message group)
        self.group_index: dict[str, int] = {}  # message group -> a number, for the compiled checks
        self.group_ids = np.full(self.scenario.agents, -1, dtype=np.int64)  # agent -> its group's number
        self._publishers: dict[str, object] = {}  # message group -> its declared observation publisher
        self._grouping: tuple[bytes, int, dict] | None = None  # (active agents, joins, their groups) of the last tick
        self.stats = Stats()
        self.tick = 0
        self.events: queue.SimpleQueue = queue.SimpleQueue()  # bounded by the gate's budgets
        self.gate = Gate(allowances(self.scenario.agents), self.group_index, self.window())
        self.started = 0.0
        self._due = 0.0  # when the current real-time tick's answers are due (0: the clock has not started)

    def _open_session(self, listen: str | None, connect: str | None, identity: Identity | None) -> None:
        """The zenoh session, with the join, info, action, liveliness, shared and state keys declared.
        `identity`: a secure run's credentials (the router's when hosting it, the world's when joining one)."""
        self.session = (open_client(connect, identity=identity) if connect
                        else open_router(listen or "tcp/127.0.0.1:7447", identity))  # fmt: skip
        put = self.events.put
        k = self.keys
        self._decls = [
            self.session.declare_queryable(k.join, self.on_query("join", "join", put)),
            self.session.declare_queryable(k.info, self.on_query("info", "info", put)),
            # history: tokens declared before this subscriber (agents back before a restarted world) count too
            self.session.liveliness().declare_subscriber(k.alive_all, self._on_liveliness(put), history=True),
            *self.kind.declare(put),
        ]
        self._state_publisher = self.session.declare_publisher(k.state)
        self._next_state = 0.0  # when progress goes out on the state key next

    # --------------------------------------------------- what a world kind uses

    def on_put(self, space: str, event: str, put: Callable[[tuple[str, Any]], None]) -> Callable[[Any], None]:
        """A subscriber's callback for the gate's key space `space`: a put its sender's budget lets in
        goes to the world's thread as (event, (bytes, sender)); the rest is counted and dropped."""
        take = self.gate.take

        def callback(sample) -> None:
            if (got := take(space, sample)) is not None:
                put((event, got))

        return callback

    def _on_liveliness(self, put: Callable[[tuple[str, Any]], None]) -> Callable[[Any], None]:
        """The liveliness subscriber's callback: a token the world waits for (a joining agent's
        appearing, a member's going) and, within their own budget, the others go to the world's thread."""
        let_alive, slots = self.gate.let_alive, self.slots

        def callback(sample) -> None:
            agent, gone = self._sender(sample), sample.kind == zenoh.SampleKind.DELETE
            if agent is not None and not 0 <= agent < len(slots):
                agent = None
            awaited = agent is not None and (slots[agent] == JOINING or (gone and slots[agent] == ACTIVE))
            if let_alive(awaited):
                put(("alive", (agent, gone)))

        return callback

    def on_query(self, space: str, event: str, put: Callable[[tuple[str, Any]], None],
                 item: Callable[[Any], Any] = lambda query: query) -> Callable[[Any], None]:  # fmt: skip
        """A queryable's callback: a query the budget of `space` lets in goes to the world's thread as
        (event, item(query)); the rest is dropped unanswered and counted."""
        let_in = self.gate.let_in
        return lambda query: put((event, item(query))) if let_in(space, query) else None

    @property
    def world(self):
        """The kind's world (world_server.contract.World)."""
        return self.kind.world

    def check_same_scenario(self, saved: str, state_file: Path) -> None:
        """A run id names one run: a saved state of another scenario is refused (one line)."""
        if saved != self.scenario.describe():
            raise ScenarioError(str(state_file), "run id", f"holds run {self.keys.run!r} of another scenario; "
                                "use another --run-id or remove the file")  # fmt: skip

    def membership(self) -> dict:
        """What a saved state keeps of the run's membership and counts (the `stats` of its meta)."""
        return {"joins": self.stats.joins, "agents_lost": self.stats.agents_lost, "rejected": self.stats.rejected,
                "groups": {str(a): g for a, g in self.group_of.items()}}  # fmt: skip

    def resume_membership(self, tick: int, slots: np.ndarray, stats: dict) -> None:
        """A saved run's tick, slots and counts: the agents that were in come back when their
        liveliness token reappears (a newcomer takes over one that does not)."""
        self.tick = tick
        self.gate.window = self.window()
        self.slots[:] = np.where((slots == ACTIVE) | (slots == JOINING), JOINING, slots)
        self.returning[:] = self.slots == JOINING
        self.stats.joins = int(stats.get("joins", 0))
        self.stats.agents_lost = int(stats.get("agents_lost", 0))
        self.stats.rejected = dict(stats.get("rejected", {}))
        for a, g in stats.get("groups", {}).items():
            self.assign_group(int(a), g)

    def saves_after(self, tick: int) -> bool:
        """Is the world saved once `tick` is resolved (controllers' memory is wanted with its actions)?"""
        return bool(self.persist_every) and self.state_dir is not None and (tick + 1) % self.persist_every == 0

    def free_slots(self) -> np.ndarray:
        """Slots a newcomer may take, in order: first those of a resumed run
        whose agents have not come back (the newcomer continues that agent
        exactly: its body and its controller's memory), then free ones."""
        free = np.flatnonzero((self.slots == FREE) | (self.slots == LOST))
        return np.concatenate([np.flatnonzero(self.returning), free])

    def _recorder(self, record: str, viewer: str | None):
        """A resumed run records into a new file from its resume tick: the
        first file stays as it was (rerun merges files of one recording id).
        `record` may name a folder (ending in /): the file is then
        <run-id>-<UTC time>.rrd in it, as containers write to a mounted folder."""
        path = Path(record)
        if record.endswith("/") or path.is_dir():  # a folder: one new file per run, never overwritten
            path = path / f"{self.keys.run}-{time.strftime('%Y%m%d-%H%M%S', time.gmtime())}.rrd"
        elif self.resumed and path.exists():
            path = path.with_name(f"{path.stem}.from-{self.tick}{path.suffix}")
        self.recording_path = str(path)
        if self.services.open_recorder is None:
            raise ValueError("this world process was started without a recorder (swarm.world_process starts one)")
        return self.services.open_recorder(self, path, viewer)

    # ---------------------------------------------------------------- messages

    def _handle(self, kind: str, item) -> None:
        if kind == "join":
            self._on_join(item)
        elif kind == "info":
            self.reply(item, self.keys.info, wire.pack(self.info()))
        elif kind == "alive":
            self._on_alive(item)
        elif kind == "wake":
            pass  # the barrier looks again (`may_all_have_answered`)
        else:  # the kind's: actions and its shared key spaces
            self.kind.handle(kind, item)

    def reply(self, query, key: str, payload: bytes) -> None:
        try:
            query.reply(key, payload)
        finally:
            query.drop()

    def _on_join(self, query) -> None:
        raw = query.payload.to_bytes() if query.payload is not None else b""
        request = wire.parse_join(raw)
        if isinstance(request, wire.Rejected):
            self.stats.reject(f"join: {request.reason}")
            self.reply(query, self.keys.join, wire.refuse_reply(request.reason))
            return
        if isinstance(free := self.kind.admit(request), str):
            self.reply(query, self.keys.join, wire.refuse_reply(free))
            return
        if self.final is not None:
            self.reply(query, self.keys.join, wire.refuse_reply(wire.ENDED))
            return
        nonce = request["nonce"]
        agent = self.nonces.get(nonce)  # a retried join gets the same id
        replacing = False
        if agent is None:
            if len(free) == 0:
                self.reply(query, self.keys.join, wire.refuse_reply("the swarm is full"))
                return
            agent = int(free[0])
            if self.returning[agent]:
                self.returning[agent] = False  # taken over where it was saved
            else:
                replacing = bool(self.slots[agent] == LOST)
            self.nonces[nonce] = agent
            self.assign_group(agent, request["group"])
            self.slots[agent] = JOINING
            self.misses[agent] = 0
            self.stats.joins += 1
        info = {"run": self.keys.run, "seed": self.scenario.seed, "tick": self.tick,
                "lockstep": self.mode == "lockstep", **self.kind.welcome(agent, replacing)}  # fmt: skip
        self.reply(query, self.keys.join, wire.join_reply(agent, nonce, info))

    def assign_group(self, agent: int, group: str) -> None:
        self.group_of[agent] = group
        self.group_ids[agent] = self.group_index.setdefault(group, len(self.group_index))

    def _on_alive(self, item: tuple[int | None, bool]) -> None:
        """(agent, gone) of a liveliness change the gate let in (`_on_liveliness`); None: not a slot's key."""
        agent, gone = item
        if agent is None:
            return
        if not gone and self.slots[agent] == JOINING:
            self.slots[agent] = ACTIVE
            self.returning[agent] = False
        elif gone and self.slots[agent] in (JOINING, ACTIVE):
            self._lose(agent)

    def _lose(self, agent: int) -> None:
        self.slots[agent] = LOST
        self.returning[agent] = False
        self.stats.agents_lost += 1
        if not self.kind.done():  # after the run, agents leaving do not change the final world
            self.kind.remove(agent)
        for nonce, a in list(self.nonces.items()):
            if a == agent:
                del self.nonces[nonce]

    def _sender(self, sample) -> int | None:
        try:
            return int(str(sample.key_expr).rsplit("/", 1)[1])
        except ValueError:
            return None

    def receive(self, item: tuple[bytes, str], parse, what: str):
        """(message, sending group) of a put the gate let in (`on_put`), or None after counting a rejection."""
        raw, group = item
        self.bytes_in += len(raw)
        msg = parse(raw)
        if isinstance(msg, wire.Rejected):
            self.stats.reject(f"{what}: {msg.reason}")
            return None
        return msg, group

    def acting(self, a: int, group: str, tick: int) -> bool:
        """May agent `a` of process `group` act for `tick` now?  Counts why not."""
        if not (0 <= a < len(self.slots)) or self.slots[a] != ACTIVE:
            self.stats.reject("act: unknown agent")
        elif self.group_of.get(a) != group:
            self.stats.reject("act: names an agent of another process")
        elif not self.current(tick):
            self.stats.late_actions += 1
            self.stats.reject("act: not for this tick")
        elif self.acted[a] and self.mode == "lockstep":  # in real time the latest action wins
            self.stats.reject("act: second action in one tick")
        else:
            return True
        return False

    def window(self) -> tuple[int, int]:
        """The ticks an action may be for now.  Lock-step: only this tick.  Real
        time: this tick or the two before (an agent may answer a slightly old
        observation)."""
        if self.mode == "lockstep":
            return self.tick, self.tick
        return self.tick - 2, self.tick

    def current(self, tick: int) -> bool:
        first, last = self.window()
        return first <= tick <= last

    def drain(self, timeout: float) -> bool:
        """Handle queued events; wait up to `timeout` for the first one."""
        try:
            kind, item = self.events.get(timeout=timeout)
        except queue.Empty:
            return False
        self._handle(kind, item)
        events = self.events
        while not events.empty():  # we are its only reader: not empty, so get_nowait cannot fail
            self._handle(*events.get_nowait())
        return True

    # ------------------------------------------------------------------ ticks

    def wait_for_agents(self) -> None:
        if self.resumed:
            deadline = time.monotonic() + self.resume_timeout
            while (self.slots == JOINING).any() and time.monotonic() < deadline:
                self.drain(0.05)
            for agent in np.flatnonzero(self.slots == JOINING):
                self._lose(int(agent))  # did not come back
            return
        deadline = time.monotonic() + self.start_timeout
        while int((self.slots == ACTIVE).sum()) < self.start_with:
            if time.monotonic() > deadline:
                raise TimeoutError(f"only {int((self.slots == ACTIVE).sum())} of {self.start_with} agents joined")
            self.drain(0.05)

    def _wait_for_any_agent(self) -> None:
        deadline = time.monotonic() + self.start_timeout
        while not (self.slots == ACTIVE).any():
            if time.monotonic() > deadline:
                raise TimeoutError(f"every agent is gone and none joined for {self.start_timeout:g} s; "
                                   "start agents with `swarm agent --run-id ...`")  # fmt: skip
            self.drain(0.05)

    def step(self) -> None:
        started, begun = time.perf_counter(), time.monotonic()
        tick = self.tick
        active = np.flatnonzero(self.slots == ACTIVE)
        self.acted[:] = False
        for group, payload in self.kind.observe(tick, self.grouped(active)):
            self.bytes_out += len(payload)
            self.publisher(group).put(payload)
        if self.mode == "lockstep":  # a barrier: until all have answered or the deadline
            deadline = time.monotonic() + self.deadline
            while not (self.kind.may_all_have_answered(active) and self.acted[active].all()):
                left = deadline - time.monotonic()
                if left <= 0:
                    break
                self.drain(left)
        else:  # real time: the tick ends on the world's clock, whoever has answered
            self._due = self._beat(begun)
            while (left := self._due - time.monotonic()) > 0:
                self.drain(left)
        self.kind.barrier_passed()
        answered = self.acted[active]
        self.agent_steps += int(answered.sum())
        self.misses[active[answered]] = 0
        missed = []
        for a in active[~answered].tolist():  # a Python loop over the few that missed, not over everyone
            if self.slots[a] == ACTIVE:
                self.misses[a] += 1
                self.stats.missed_ticks += 1
                missed.append(a)
                if self.misses[a] >= self.max_misses:
                    self._lose(a)
        self.kind.resolve(tick, np.array(missed, np.int64))
        self.tick += 1
        self.gate.window = self.window()  # the budgets' tick, and the ticks an answer may be for now
        if self.persist_every and self.tick % self.persist_every == 0:
            self.kind.save()
        self.tick_seconds.append(time.perf_counter() - started)
        self._count_dropped()
        present = self.slots == ACTIVE
        self.agents_peak = max(self.agents_peak, int(present.sum()))
        if self.recorder is not None:
            self.recorder.capture(tick, present=present, tick_ms=self.tick_seconds[-1] * 1000,
                                  rejected=self.stats.rejected_total)  # fmt: skip
        if (now := time.monotonic()) >= self._next_state:  # progress for people: ten times a second is plenty
            self._next_state = now + STATE_PERIOD
            self._state_publisher.put(wire.pack({"type": "state", **self.progress()}))

    def _beat(self, now: float) -> float:
        """When the real-time tick begun `now` has its answers due: one period after the last tick's, so the
        world's own work between two ticks (and a short stall of the machine) does not slow the rate.  Where
        that would leave less than half a period, the clock slips, and counts it: the tick lasts a whole
        period from its beginning, as the first does, so the agents always have half a period at least."""
        due = self._due + self.period
        if due - now < self.period / 2:
            if self._due:  # the first tick starts the clock
                self.stats.clock_slips += 1
            due = now + self.period
        return due

    def _count_dropped(self) -> None:
        """What the gate dropped since the last count, into the run's rejections (on the world's thread)."""
        for reason, count in self.gate.take_dropped().items():
            self.stats.reject(reason, count)

    def grouped(self, agents: np.ndarray) -> dict[str, np.ndarray]:
        """The active agents by agent process, worked out again only when
        the active set or the joins have changed since the last tick."""
        key = agents.tobytes()
        if self._grouping is not None and self._grouping[:2] == (key, self.stats.joins):
            return self._grouping[2]
        groups: dict[str, list[int]] = {}
        for a in agents.tolist():
            groups.setdefault(self.group_of[a], []).append(a)
        grouped = {g: np.array(members, dtype=np.int64) for g, members in groups.items()}
        self._grouping = (key, self.stats.joins, grouped)
        for gone in set(self._publishers) - set(grouped):
            self._publishers.pop(gone).undeclare()
        return grouped

    def publisher(self, group: str):
        if (pub := self._publishers.get(group)) is None:
            # lock-step: every observation arrives; real time: an observation the link has no room for
            # is dropped, as the next supersedes it and a slow agent must not hold the world's tick
            lossless = {"congestion_control": LOSSLESS} if self.mode == "lockstep" else {}
            pub = self._publishers[group] = self.session.declare_publisher(self.keys.obs(group), **lossless)
        return pub

    def hand_back(self, group: str, payload: bytes) -> None:
        """Controllers' saved memory to an agent process, on its observation key so that it arrives
        before the next observation, and never dropped (real time's observations may be)."""
        self.session.put(self.keys.obs(group), payload, congestion_control=LOSSLESS)

    def run(self) -> dict:
        if not (self.resumed and self.kind.done()):  # a finished run resumed has nothing left to do
            self.wait_for_agents()
        self.kind.start(self.resumed)
        self.started = time.monotonic()
        while not self.kind.done() and self.tick < self.max_iterations:
            if not (self.slots == ACTIVE).any():
                self._wait_for_any_agent()  # a world with nobody in it does not tick on alone
                self._due = 0.0  # nor does its clock: it starts again with the next tick
            self.step()
        self.drain(0.0)
        self.kind.finish()
        self.kind.save()
        self.final = summary = self.summary()
        self._close_recording(summary)
        return summary

    def _close_recording(self, summary: dict) -> None:
        if self.recorder is not None:
            self.recorder.close(summary)
            self.recorder = None

    def linger(self, until) -> None:
        """Keep serving the key space (shared spaces, info) after the run until
        `until()` is true: clients can still read the final environment."""
        while not until():
            self.drain(0.1)

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
        elapsed = time.monotonic() - self.started if self.started else 0.0
        return {"tick": self.tick, **self.kind.progress(), "agents_alive": int((self.slots == ACTIVE).sum()),
                "ticks_per_second": round(self.tick / elapsed, 2) if elapsed > 0 else 0.0}  # fmt: skip

    def summary(self) -> dict:
        self._count_dropped()
        elapsed = time.monotonic() - self.started if self.started else 0.0
        return {
            **self.kind.summary(), "run_id": self.keys.run, "mode": self.mode,
            "rejected_messages": self.stats.rejected_total, "rejected_by_reason": dict(self.stats.rejected),
            "agents_lost": self.stats.agents_lost, "joins": self.stats.joins, "missed_ticks": self.stats.missed_ticks,
            "agents_peak": self.agents_peak,
            **({"clock_slips": self.stats.clock_slips} if self.mode == "realtime" else {}),
            "ticks_per_second": round(self.tick / elapsed, 2) if elapsed > 0 else 0.0,
            "wall_seconds": round(elapsed, 3), **self._latency(), "recording": self.recording_path,
        }  # fmt: skip

    def _latency(self) -> dict:
        ticks = np.array(self.tick_seconds) * 1000 if self.tick_seconds else np.zeros(1)
        return {"tick_ms_p50": round(float(np.percentile(ticks, 50)), 3),
                "tick_ms_p99": round(float(np.percentile(ticks, 99)), 3), "tick_ms_max": round(float(ticks.max()), 3),
                "payload_bytes_out": self.bytes_out, "payload_bytes_in": self.bytes_in,
                "agent_steps": self.agent_steps}  # fmt: skip

    def stop_agents(self, reason: str) -> None:
        for group in set(self.group_of.values()):
            self.session.put(self.keys.obs(group), wire.stop_message(reason), congestion_control=LOSSLESS)

    def close(self) -> None:
        if self.recorder is not None:  # an interrupted run still ends its recording
            self._close_recording(self.summary())
        for d in [*self._decls, *self._publishers.values(), self._state_publisher]:
            d.undeclare()
        self.kind.close()
        self.session.close()


def new_run_id() -> str:
    return uuid.uuid4().hex[:8]
