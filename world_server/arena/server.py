"""The arena's world kind: what binds world_server.server.WorldServer to the arena.

Each tick the world casts every robot's rays once (ArenaWorld.perceive), sends
each agent process its agents' readings, and integrates one control period
from the wheel speeds that came back.  An agent that is late, silent, or whose
wheel speeds are refused holds still that tick.  A lost agent's body stays
where it stopped, an obstacle to the others; a newcomer taking the slot over
drives that body on from there with a fresh controller.  Agents join the
slots of the scenario group whose controller they run, so one scenario can
mix controllers.  What the run asks of the robots (goals, routes, dwell, L_o)
the runner lends the world process (RunnerServices.goals): it is kept above the world.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from swarm.core import wire
from world_server import persist
from world_server.arena.face import wire as arena_proto
from world_server.arena.scenario import controller_params
from world_server.arena.world import ArenaWorld
from world_server.history import SharedHistory, ShareLog
from world_server.server import ACTIVE, FREE, LOST, WorldServer


class ArenaKind:
    """The arena bound to the world process (world_server.server.WorldKind)."""

    family = wire.FAMILY_ARENA

    def __init__(self, server: WorldServer):
        self.server = server
        s = self.scenario = server.scenario
        if server.services.goals is None:
            raise ValueError("this arena was started without its goals (swarm.world_process lends them)")
        self.world = ArenaWorld(s, parked=True)  # robots come in as their agents join
        self.goals = server.services.goals(s)
        self.world.cast(np.zeros(1, np.int64), np.zeros(1), np.ones(1))  # compile the ray pass now, not in a deadline
        self.controllers = np.array([g.controller for g in s.groups for _ in range(g.count)])
        self.wheels = np.zeros((self.world.n, 3))  # wheel speeds and an act
        self.ok = np.zeros(self.world.n, np.bool_)
        self.pending_shared: dict[int, tuple[str, bytes]] = {}  # this tick's publications, by agent
        self.shared_out: list[tuple[int, str, bytes]] = []  # last tick's, going out with this tick's observations
        self.shares = ShareLog()
        self.memory: list[bytes | None] = [None] * self.world.n  # each controller's memory at the last save
        self.recorded_tick = np.full(self.world.n, -1, np.int64)  # the last tick of each robot's record() logged
        self.record_due = np.full(self.world.n, -1, np.int64)  # the last tick an action said a record() was sent
        self.state_file = Path(server.state_dir) / f"{server.keys.run}.arena.npz" if server.state_dir else None
        # every publication, for `get <share>/**`, kept across a restart
        self.shared_history = SharedHistory(self.state_file.with_suffix(".shared.msgpack") if self.state_file else None)
        if server.persist_every:  # saves fall on physics checkpoints, the ticks a resumed run is exact from
            server.persist_every = math.lcm(server.persist_every, s.checkpoint)

    # ------------------------------------------------------------ persistence

    def resume(self) -> bool:
        """Continue a run persisted under this run id, if there is one: the
        robots where they were, their counters, the agents' slots (the agents
        that were in come back when their liveliness token reappears)."""
        loaded = persist.load_arrays(self.state_file) if self.state_file else None
        if loaded is None:
            return False
        arrays, meta = loaded
        with persist.resuming(self.state_file):
            self.server.check_same_scenario(meta["scenario"], self.state_file)
            self.world.restore(arrays)
            self.goals.restore(arrays)
            self.server.resume_membership(int(arrays["tick"]), arrays["slots"], meta["stats"])
            self.memory = persist.unpack_blobs(arrays["memory"], arrays["memory_at"])
            payloads = persist.unpack_blobs(arrays["pending"], arrays["pending_at"])
            pending = zip(arrays["pending_agents"].tolist(), arrays["pending_shares"].tolist(), payloads, strict=True)
            self.pending_shared = {a: (s, p) for a, s, p in pending}
            self.shares.restore(meta["shares"])
        self.shared_history.open(keep_before=self.server.tick - 1)  # the last tick's publications go out again
        return True

    def save(self) -> None:
        if self.state_file is None:
            return
        w, tick = self.world, self.server.tick
        world = w.checkpointed if w.checkpointed is not None and w.tick == tick else w.snapshot()
        memory, memory_at = persist.pack_blobs(self.memory)
        pending = sorted(self.pending_shared.items())  # the last tick's publications, out with the next tick's
        payloads, payloads_at = persist.pack_blobs([p for _, (_, p) in pending])
        arrays = {**world, **self.goals.snapshot(), "slots": self.server.slots, "memory": memory,
                  "memory_at": memory_at,
                  "pending_agents": np.array([a for a, _ in pending], np.int64),
                  "pending_shares": np.array([s for _, (s, _) in pending], dtype=np.str_).reshape(-1),
                  "pending": payloads, "pending_at": payloads_at}  # fmt: skip
        meta = {"scenario": self.scenario.describe(), "stats": self.server.membership(), "shares": self.shares.state()}
        self.shared_history.flush()
        persist.save_arrays(self.state_file, arrays, meta)

    def declare(self, put) -> list:
        """Action messages, the plans and records agents send for the recording, and the controllers'
        shared key spaces."""
        s, k = self.server, self.server.keys
        out = [s.session.declare_subscriber(k.acts, s.on_put("act", "act", put)),
               s.session.declare_subscriber(k.plans, s.on_put("plan", "plan", put))]  # fmt: skip
        if s.recorder is not None:
            out.append(s.session.declare_subscriber(k.records, s.on_put("record", "record", put)))
        shares = {self.scenario.share_of(c) for c in set(self.controllers.tolist())} - {None}
        for share in sorted(shares):
            asked = s.on_query("shared query", "shared?", put, lambda q, share=share: (share, q))
            out.append(s.session.declare_queryable(f"{k.prefix}/{share}/**", asked))
        return out

    def handle(self, event: str, item) -> None:
        if event == "act":
            self._on_act(item)
        elif event == "shared?":
            self._on_shared_query(*item)
        elif event == "plan":
            self._on_recorded(item, arena_proto.parse_plan, "plan", lambda r, m: r.log_plan(m.tick, m.agent, m.path))
        elif event == "record":
            self._on_recorded(item, arena_proto.parse_record, "record", self._log_record)

    def _on_recorded(self, item: tuple[bytes, str], parse, what: str, log) -> None:
        """A plan or a record() an agent process sends for the recording, logged when it names one of the
        process's own agents."""
        s = self.server
        received = s.receive(item, parse, what)
        if received is None:
            return
        message, group = received
        if not (0 <= message.agent < len(s.slots)) or s.group_of.get(message.agent) != group:
            s.stats.reject(f"{what}: names an agent of another process")
        elif s.recorder is not None:
            log(s.recorder, message)

    def _log_record(self, recorder, message: arena_proto.Record) -> None:
        recorder.log_record(message.tick, message.agent, message.values)
        self.recorded_tick[message.agent] = max(self.recorded_tick[message.agent], message.tick)

    def _await_last_records(self) -> None:
        """A record() rides its own key, so the last tick's may still be on its way when that tick's actions
        are in: wait (at most the tick deadline) for those the actions said were sent, from every active
        robot.  A record() with no number in it goes out only on the ticks that carry its arrays, so the
        last tick's action is what tells whether one is coming."""
        s = self.server
        if s.recorder is None:
            return
        until = time.monotonic() + s.deadline
        while ((self.recorded_tick < self.record_due) & (s.slots == ACTIVE)).any() and time.monotonic() < until:
            s.drain(0.05)

    # ------------------------------------------------------------------ joins

    def admit(self, request: dict) -> np.ndarray | str:
        """The slots of the request's controller: a resumed run's missing agents first (taken over where
        they were saved), then free slots."""
        if request.get("family") != self.family or request.get("controller") not in set(self.controllers):
            wanted = ", ".join(sorted(set(self.controllers)))
            return f"this arena's robots run {wanted}, not {request.get('controller')!r}"
        s = self.server
        mine = self.controllers == request.get("controller")
        free = (s.slots == FREE) | (s.slots == LOST)
        return np.concatenate([np.flatnonzero(s.returning & mine), np.flatnonzero(free & mine)])

    def welcome(self, agent: int, replacing: bool) -> dict:
        """A newcomer in a lost agent's place drives that body on with its controller started afresh."""
        if replacing:
            self.world.present[agent] = True
            self.memory[agent] = None
        welcome = {"family": self.family, "controller": str(self.controllers[agent]),
                   "params": controller_params(self.scenario, agent),
                   "recorded": self.server.recorder is not None}  # fmt: skip
        if self.memory[agent] is not None:
            welcome["memory"] = self.memory[agent]
        return welcome

    def start(self, resumed: bool) -> None:
        """The robots that start the run come in together, in id order: the
        same draws as the in-process engine when every agent starts it.
        Agents that survived the world's restart ran on past the saved tick:
        their controllers go back to the saved memory (on the observation key,
        so it arrives before the first observation)."""
        s = self.server
        self.world.enter(np.flatnonzero(s.slots == ACTIVE))
        self.shared_history.open(keep_before=None)  # a fresh run (a resumed one opened it already)
        if not resumed:
            return
        for group, agents in s.grouped(np.flatnonzero(s.slots == ACTIVE)).items():
            memory = [(a, self.memory[a]) for a in agents.tolist() if self.memory[a] is not None]
            if memory:
                s.hand_back(group, arena_proto.memory_message(memory))

    def remove(self, agent: int) -> None:
        self.world.remove_agent(agent)

    def finish(self) -> None:
        self._await_last_records()
        self._pass_on_shared()  # the last tick's publications go on their keys too: nothing written is lost
        self.shared_history.flush()

    def close(self) -> None:
        self.shared_history.close()

    # ------------------------------------------------------------------ ticks

    def observe(self, tick: int, groups: dict[str, np.ndarray]) -> list[tuple[str, bytes]]:
        """Late joiners come in beside the others, last tick's publications go out, and every robot
        perceives the start-of-tick world in one ray pass."""
        s = self.server
        active = np.flatnonzero(s.slots == ACTIVE)
        self.world.enter(active)
        self.ok[:] = False
        self.wheels[:] = 0.0
        keep = s.saves_after(tick)
        if keep:  # an agent that does not answer this tick has no saved memory
            for a in active.tolist():
                self.memory[a] = None
        self._pass_on_shared()
        if s.null:
            return [(group, arena_proto.observations(tick, agents, [{} for _ in agents], self.shared_out, keep=keep))
                    for group, agents in groups.items()]  # fmt: skip
        readings = self.world.perceive()
        return [(group, arena_proto.observations(tick, agents, [readings[a] for a in agents], self.shared_out,
                                                 keep=keep)) for group, agents in groups.items()]  # fmt: skip

    def may_all_have_answered(self, agents: np.ndarray) -> bool:
        return True

    def barrier_passed(self) -> None:
        pass

    def _on_act(self, item: tuple[bytes, str]) -> None:
        s = self.server
        received = s.receive(item, arena_proto.parse_acts, "act")
        if received is None:
            return
        msg, group = received
        taken, answered = set(), set()  # the agents whose action this message gave; those it answered for
        for a, wheels in zip(msg.agents.tolist(), msg.wheels, strict=True):
            if not s.acting(a, group, msg.tick):
                continue
            answered.add(a)
            if (reason := self.world.judge(a, wheels)) is not None:
                s.stats.reject(f"act: {reason}")
                s.acted[a] = True  # an answer, refused: its robot holds still this tick, as in process
            else:
                self.wheels[a] = 0.0
                self.wheels[a, : len(wheels)] = wheels
                self.ok[a] = True
                s.acted[a] = True
                taken.add(a)
        if msg.shared:
            self._take_shared(msg, group, answered)
        self.world.broadcast([(a, data) for a, data in msg.rab if a in taken])  # heard next tick, as in-process
        for a in msg.records:
            if a in answered:
                self.record_due[a] = max(self.record_due[a], msg.tick)
            else:
                s.stats.reject("act: records names an agent it did not act for")
        for a, blob in msg.memory:
            if a in taken and s.group_of.get(a) == group and s.saves_after(msg.tick):
                self.memory[a] = blob
            else:
                s.stats.reject("memory: not with an accepted action before a save")

    def _take_shared(self, msg, group: str, answered: set[int]) -> None:
        """Publications of the agents this message answered for this tick (a late or second message's,
        say a copy of an earlier one, would overwrite the publication of the answer taken); the rest is
        counted and dropped."""
        s = self.server
        named = set(msg.agents.tolist())
        for a, share, payload in msg.shared:
            if not (0 <= a < len(s.slots)) or s.group_of.get(a) != group or a not in named:
                s.stats.reject("shared: names an agent of another process")
            elif share != self.scenario.share_of(str(self.controllers[a])):
                s.stats.reject("shared: not this controller's key space")
            elif a not in answered:
                s.stats.reject("shared: its agent's action was refused")
            else:
                self.pending_shared[a] = (share, payload)

    def _pass_on_shared(self) -> None:
        """Last tick's publications: on their keys, and out with this tick's observations."""
        s, tick = self.server, self.server.tick
        self.shared_out = [(a, *self.pending_shared[a]) for a in sorted(self.pending_shared)]
        self.pending_shared = {}
        if self.shared_out:
            self.shares.add(tick - 1, self.shared_out)
        for a, share, payload in self.shared_out:
            self.shared_history.add(tick - 1, share, a, payload)
            s.session.put(f"{s.keys.prefix}/{share}/{a}", payload)
            if s.recorder is not None and share == "map":
                data = wire.unpack(payload, len(payload) + 1)
                if not isinstance(data, wire.Rejected):
                    s.recorder.log_published_map(tick - 1, a, data)

    def _on_shared_query(self, share: str, query) -> None:
        """Every publication of every agent in the key space, one reply per agent."""
        try:
            for a, history in self.shared_history.of(share):
                query.reply(f"{self.server.keys.prefix}/{share}/{a}", wire.pack({"agent": a, "updates": history}))
        finally:
            query.drop()

    def resolve(self, tick: int, missed: np.ndarray) -> None:
        """One control period integrated (late and refused robots hold still), then the run's goals."""
        if not self.server.null:
            self.world.apply(self.wheels, self.ok)
            self.goals.track(self.world)

    def done(self) -> bool:
        return self.world.done() or self.goals.done(self.world)

    # ---------------------------------------------------------------- summary

    def progress(self) -> dict:
        return {"reached": int(self.world.finished.sum()), "with_goal": int(self.goals.has_goal.sum())}

    def summary(self) -> dict:
        out = self.goals.summary(self.world, 0.0, "distributed")
        for key in ("wall_seconds", "ticks_per_second"):  # the runtime's own, the server adds them
            out.pop(key)
        for robot in out["robots"]:
            if (shared := self.shares.of(robot["agent"])) is not None:
                robot["shared"] = shared
        return {**out, "until": self.server.until}
