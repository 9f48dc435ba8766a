"""The arena's world process: world_server.server bound to the arena.

Each tick the world casts every robot's rays once (ArenaWorld.perceive), sends
each agent process its agents' readings, and integrates one control period
from the wheel speeds that came back.  An agent that is late, silent, or whose
wheel speeds are refused holds still that tick.  A lost agent's body stays
where it stopped, an obstacle to the others; a newcomer taking the slot over
drives that body on from there with a fresh controller.  Agents join the
slots of the scenario group whose controller they run, so one scenario can
mix controllers.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from swarm.core import wire
from world_server import persist
from world_server.arena.face import wire as arena_proto
from world_server.arena.scenario import controller_params
from world_server.arena.summary import arena_summary
from world_server.arena.world import ArenaWorld
from world_server.history import SharedHistory, ShareLog
from world_server.server import ACTIVE, FREE, JOINING, LOST, WorldServer


class ArenaServer(WorldServer):
    family = wire.FAMILY_ARENA

    def _make_world(self) -> None:
        s = self.scenario
        self.world = ArenaWorld(s, parked=True)  # robots come in as their agents join
        self.world.cast(np.zeros(1, np.int64), np.zeros(1), np.ones(1))  # compile the ray pass now, not in a deadline
        self.controllers = np.array([g.controller for g in s.groups for _ in range(g.count)])
        self.wheels = np.zeros((self.world.n, 3))  # wheel speeds and an act
        self.ok = np.zeros(self.world.n, np.bool_)
        self.readings: list[dict[str, np.ndarray]] = []
        self.pending_shared: dict[int, tuple[str, bytes]] = {}  # this tick's publications, by agent
        self.shared_out: list[tuple[int, str, bytes]] = []  # last tick's, going out with this tick's observations
        self.shares = ShareLog()
        self.memory: list[bytes | None] = [None] * self.world.n  # each controller's memory at the last save
        self.state_file = Path(self.state_dir) / f"{self.keys.run}.arena.npz" if self.state_dir else None
        # every publication, for `get <share>/**`, kept across a restart
        self.shared_history = SharedHistory(self.state_file.with_suffix(".shared.msgpack") if self.state_file else None)
        if self.persist_every:  # saves fall on physics checkpoints, the ticks a resumed run is exact from
            self.persist_every = math.lcm(self.persist_every, s.checkpoint)

    # ------------------------------------------------------------ persistence

    def _resume(self) -> bool:
        """Continue a run persisted under this run id, if there is one: the
        robots where they were, their counters, the agents' slots (the agents
        that were in come back when their liveliness token reappears)."""
        loaded = persist.load_arrays(self.state_file) if self.state_file else None
        if loaded is None:
            return False
        arrays, meta = loaded
        self._check_same_scenario(meta["scenario"])
        self.world.restore(arrays)
        self.tick = int(arrays["tick"])
        slots = arrays["slots"]
        self.slots[:] = np.where((slots == ACTIVE) | (slots == JOINING), JOINING, slots)
        self.returning[:] = self.slots == JOINING
        self.memory = persist.unpack_blobs(arrays["memory"], arrays["memory_at"])
        payloads = persist.unpack_blobs(arrays["pending"], arrays["pending_at"])
        pending = zip(arrays["pending_agents"].tolist(), arrays["pending_shares"].tolist(), payloads, strict=True)
        self.pending_shared = {a: (s, p) for a, s, p in pending}
        self.shares.restore(meta["shares"])
        self.shared_history.open(keep_before=self.tick - 1)  # the last tick's publications go out again
        self.stats.joins = int(meta["stats"]["joins"])
        self.stats.agents_lost = int(meta["stats"]["agents_lost"])
        self.stats.rejected = dict(meta["stats"]["rejected"])
        for a, g in meta["stats"]["groups"].items():
            self._assign_group(int(a), g)
        return True

    def save_state(self) -> None:
        if self.state_file is None:
            return
        stats = {"joins": self.stats.joins, "agents_lost": self.stats.agents_lost, "rejected": self.stats.rejected,
                 "groups": {str(a): g for a, g in self.group_of.items()}}  # fmt: skip
        w = self.world
        world = w.checkpointed if w.checkpointed is not None and w.tick == self.tick else w.snapshot()
        memory, memory_at = persist.pack_blobs(self.memory)
        pending = sorted(self.pending_shared.items())  # the last tick's publications, out with the next tick's
        payloads, payloads_at = persist.pack_blobs([p for _, (_, p) in pending])
        arrays = {**world, "slots": self.slots, "memory": memory, "memory_at": memory_at,
                  "pending_agents": np.array([a for a, _ in pending], np.int64),
                  "pending_shares": np.array([s for _, (s, _) in pending], dtype=np.str_).reshape(-1),
                  "pending": payloads, "pending_at": payloads_at}  # fmt: skip
        meta = {"scenario": self.scenario.describe(), "stats": stats, "shares": self.shares.state()}
        self.shared_history.flush()
        persist.save_arrays(self.state_file, arrays, meta)

    def _declare_shared(self, put) -> list:
        out = [self.session.declare_subscriber(self.keys.plans, lambda s: put(("plan", s)))]
        shares = {self.scenario.share_of(c) for c in set(self.controllers.tolist())} - {None}
        for share in sorted(shares):
            out.append(self.session.declare_queryable(f"{self.keys.prefix}/{share}/**",
                                                      lambda q, share=share: put(("shared?", (share, q)))))  # fmt: skip
        return out

    def _handle_shared(self, kind: str, item) -> None:
        if kind == "shared?":
            self._on_shared_query(*item)
            return
        if kind != "plan":
            return
        received = self._receive(item, arena_proto.parse_plan, "plan")
        if received is None:
            return
        plan, group = received
        if not (0 <= plan.agent < len(self.slots)) or self.group_of.get(plan.agent) != group:
            self.stats.reject("plan: names an agent of another process")
        elif self.recorder is not None:
            self.recorder.log_plan(plan.tick, plan.agent, plan.path)

    # ------------------------------------------------------------------ joins

    def _join_refusal(self, request: dict) -> str | None:
        if request.get("family") != self.family or request.get("controller") not in set(self.controllers):
            wanted = ", ".join(sorted(set(self.controllers)))
            return f"this arena's robots run {wanted}, not {request.get('controller')!r}"
        return None

    def _free_slots(self, request: dict) -> np.ndarray:
        """A resumed run's missing agents first (taken over where they were saved), then free slots."""
        mine = self.controllers == request.get("controller")
        free = (self.slots == FREE) | (self.slots == LOST)
        return np.concatenate([np.flatnonzero(self.returning & mine), np.flatnonzero(free & mine)])

    def _welcome(self, agent: int) -> dict:
        welcome = {"family": self.family, "controller": str(self.controllers[agent]),
                   "params": controller_params(self.scenario, agent)}  # fmt: skip
        if self.memory[agent] is not None:
            welcome["memory"] = self.memory[agent]
        return welcome

    def _hand_back(self) -> None:
        """Agents that survived the world's restart ran on past the saved tick:
        their controllers go back to the saved memory (on the observation key,
        so it arrives before the first observation)."""
        for group, agents in self._groups(np.flatnonzero(self.slots == ACTIVE)).items():
            memory = [(a, self.memory[a]) for a in agents.tolist() if self.memory[a] is not None]
            if memory:
                self._publisher(group).put(arena_proto.memory_message(memory))

    def _starting(self) -> None:
        """The robots that start the run come in together, in id order: the
        same draws as the in-process engine when every agent starts it."""
        self.world.enter(np.flatnonzero(self.slots == ACTIVE))
        self.shared_history.open(keep_before=None)  # a fresh run (a resumed one opened it already)

    def _reuse(self, agent: int) -> None:
        self.world.present[agent] = True
        self.memory[agent] = None  # a newcomer in a lost agent's place starts its controller afresh

    def _remove(self, agent: int) -> None:
        self.world.remove_agent(agent)

    # ------------------------------------------------------------------ ticks

    def _begin_tick(self) -> None:
        self.world.enter(np.flatnonzero(self.slots == ACTIVE))  # late joiners come in beside the others
        self.ok[:] = False
        self.wheels[:] = 0.0
        if self._saves_after(self.tick):  # an agent that does not answer this tick has no saved memory
            for a in np.flatnonzero(self.slots == ACTIVE).tolist():
                self.memory[a] = None
        self._pass_on_shared()
        if not self.null:
            self.readings = self.world.perceive()

    def _finish(self) -> None:
        self._pass_on_shared()  # the last tick's publications go on their keys too: nothing written is lost
        self.shared_history.flush()

    def _observe(self, tick: int, agents: np.ndarray) -> bytes:
        readings = [{} for _ in agents] if self.null else [self.readings[a] for a in agents]
        return arena_proto.observations(tick, agents, readings, self.shared_out, keep=self._saves_after(tick))

    def _on_act(self, sample) -> None:
        received = self._receive(sample, arena_proto.parse_acts, "act")
        if received is None:
            return
        msg, group = received
        for a, wheels in zip(msg.agents.tolist(), msg.wheels, strict=True):
            if not self._acting(a, group, msg.tick):
                continue
            if (reason := self.world.judge(a, wheels)) is not None:
                self.stats.reject(f"act: {reason}")
            else:
                self.wheels[a] = 0.0
                self.wheels[a, : len(wheels)] = wheels
                self.ok[a] = True
                self.acted[a] = True
        if msg.shared:
            self._take_shared(msg, group)
        for a, blob in msg.memory:
            if self.acted[a] and self.group_of.get(a) == group and self._saves_after(msg.tick):
                self.memory[a] = blob
            else:
                self.stats.reject("memory: not with an accepted action before a save")

    def _take_shared(self, msg, group: str) -> None:
        """Publications of agents whose action this tick was taken; the rest is counted and dropped."""
        named = set(msg.agents.tolist())
        for a, share, payload in msg.shared:
            if not (0 <= a < len(self.slots)) or self.group_of.get(a) != group or a not in named:
                self.stats.reject("shared: names an agent of another process")
            elif share != self.scenario.share_of(str(self.controllers[a])):
                self.stats.reject("shared: not this controller's key space")
            elif not self.acted[a]:
                self.stats.reject("shared: its agent's action was refused")
            else:
                self.pending_shared[a] = (share, payload)

    def _pass_on_shared(self) -> None:
        """Last tick's publications: on their keys, and out with this tick's observations."""
        self.shared_out = [(a, *self.pending_shared[a]) for a in sorted(self.pending_shared)]
        self.pending_shared = {}
        if self.shared_out:
            self.shares.add(self.tick - 1, self.shared_out)
        for a, share, payload in self.shared_out:
            self.shared_history.add(self.tick - 1, share, a, payload)
            self.session.put(f"{self.keys.prefix}/{share}/{a}", payload)
            if self.recorder is not None and share == "map":
                data = wire.unpack(payload, len(payload) + 1)
                if not isinstance(data, wire.Rejected):
                    self.recorder.log_published_map(self.tick - 1, a, data)

    def _on_shared_query(self, share: str, query) -> None:
        """Every publication of every agent in the key space, one reply per agent."""
        try:
            for a, history in self.shared_history.of(share):
                query.reply(f"{self.keys.prefix}/{share}/{a}", wire.pack({"agent": a, "updates": history}))
        finally:
            query.drop()

    def _resolve(self, tick: int) -> None:
        self.world.apply(self.wheels, self.ok)

    def close(self) -> None:
        self.shared_history.close()
        super().close()

    def done(self) -> bool:
        return self.world.done()

    # ---------------------------------------------------------------- summary

    def progress_fields(self) -> dict:
        w = self.world
        return {"reached": int(w.finished.sum()), "with_goal": int(w.has_goal.sum())}

    def summary_fields(self) -> dict:
        if self.services.complete_summary is not None:
            self.services.complete_summary(self.world)
        out = arena_summary(self.world, 0.0, "distributed")
        for key in ("wall_seconds", "ticks_per_second"):  # the runtime's own, below
            out.pop(key)
        for robot in out["robots"]:
            if (shared := self.shares.of(robot["agent"])) is not None:
                robot["shared"] = shared
        return {**out, "until": self.until}
