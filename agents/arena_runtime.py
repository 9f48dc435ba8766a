"""Arena agent processes: K controller objects, wheel speeds back to the world.

Each agent's controller is reset with what the world's welcome gives it (the
seed, its id, and its params: the map it is given, its goal or route, its
body), exactly as the in-process engine resets it, so lock-step runs equal
in-process runs pose for pose.  At the ticks the world saves after, each
controller's memory goes with its action; a restarted world gives it back
(or gives it to the newcomer that takes a missing agent's place), so a
resumed run goes on exactly as if nothing had happened.
"""

from __future__ import annotations

import sys

import numpy as np

from agents.controllers import CONTROLLERS
from agents.controllers.arena import StepGuard, broadcasts, deliver, make_controller, publications, record_of
from agents.runtime import AgentRuntime
from swarm.core import heap, kernels, memory_codec, wire
from swarm.core.bus import LOSSLESS
from world_server.arena.face import wire as arena_proto


class ArenaAgentRuntime(AgentRuntime):
    family = wire.FAMILY_ARENA

    def _prepare(self, count: int) -> None:
        kernels.use_ahead_of_time()  # before any controller is imported: no numba in this process when built
        self.brains: list = [None] * count
        self.names: list[str] = [self.controller] * count  # each slot's controller, as the welcome names it
        self.guard = StepGuard(self.on_error)
        self.sent_plans: dict[int, tuple] = {}  # agent -> (length, first, last point) of the last plan sent
        self.refused_shared = 0  # other robots' publications this process's controllers refused
        self.refused_memory = 0  # memories handed back that could not be decoded
        self.kept = False  # the last answer carried the controllers' memory
        self.recorded: set[int] = set()  # agents whose record() goes to the world's recording
        self.quiet: set[int] = set()  # agents whose record() failed or grew too big: told once, no longer sent

    def _welcomed(self, slot: int, agent: int, msg: dict) -> None:
        blob = msg.pop("memory", None)  # a missing agent's place, taken over where it was saved
        self.names[slot] = msg.get("controller", self.controller)
        brain = make_controller(self.names[slot])
        if msg.get("recorded") and not CONTROLLERS[self.names[slot]].records:  # no log of its own: its record()
            self.recorded.add(agent)
        self.guard.reset(brain, int(msg["seed"]), agent, msg["params"], self.names[slot])
        self.brains[slot] = brain
        heap.give_back()  # what building the controller used and freed (a DFT robot's kernels: ~5 MB)
        if isinstance(blob, bytes) and agent not in self.guard.failed:
            memory, blob = _decoded(brain, blob), None  # the blob goes before the rollback state comes
            if not self.guard.resumed_failed(memory, agent, self.names[slot]):
                self.refused_memory += not restore_or_keep(brain, memory)
            memory = None
            heap.give_back()

    def _restore(self, msg: arena_proto.ArenaMemory) -> None:
        """Each blob (a view of the message: world_server/arena/face/wire.py) is let go once decoded, before
        any rollback state is taken: for a DFT robot each is MBs (an agent process's 80 MB budget)."""
        handed = msg.memory
        while handed:
            agent, blob = handed.pop()
            if (slot := self.slot_of.get(agent)) is not None and agent not in self.guard.failed:
                memory, blob = _decoded(self.brains[slot], blob), None
                if not self.guard.resumed_failed(memory, agent, self.names[slot]):
                    self.refused_memory += not restore_or_keep(self.brains[slot], memory)
                memory = None
        heap.give_back()

    def _parse(self, data: bytes):
        return arena_proto.parse_obs(data)

    def rejections(self):
        counts = super().rejections()
        counts["memory: could not be restored"] += self.refused_memory
        counts["shared: refused by a controller"] += self.refused_shared
        return +counts  # the zero counts out

    def _answer(self, obs: arena_proto.ArenaObs) -> int:
        agents, wheels = [], []
        mine = [(self.brains[self.slot_of[a]], a) for a in obs.agents.tolist() if a in self.slot_of]
        if obs.shared and not self.null:  # what every robot published last tick, before this tick's step
            self.refused_shared += deliver(*self.guard.working(mine), list(obs.shared))
        for agent, reading in zip(obs.agents.tolist(), obs.perceptions, strict=True):
            slot = self.slot_of.get(agent)
            if slot is None:
                continue
            agents.append(agent)
            wheels.append(np.zeros(3) if self.null else
                          self.guard.action(self.brains[slot], reading, agent, self.names[slot], obs.tick))  # fmt: skip
        brains, ids = self.guard.working(mine)  # those still in the run (after this tick's steps)
        shared = [] if self.null else publications(brains, ids)
        rab = [] if self.null else broadcasts(brains, ids)
        if self.kept:  # the message that carried last tick's memory (MBs for a DFT robot) and zenoh's copy
            heap.give_back()  # of it are freed by now: all of it back to the system, not kept in the heap
        self.kept = keep = obs.keep and not self.null
        # the memory's arrays are written once, straight into the message (the save-tick peak)
        memory = [(a, memory_codec.pieces(self.guard.memory(b, a))) for b, a in mine] if keep else []
        # the records go before the action, which names them: the world awaits those at the run's end
        records = self._send_records(obs.tick, brains, ids) if self.recorded and not self.null else []
        payload = arena_proto.actions(obs.tick, agents, np.array(wheels).reshape(-1, 3), shared, memory, rab, records)
        self.act_publisher.put(payload)
        if not self.null:
            self._send_plans(obs.tick, agents)
        return len(agents)

    def _send_records(self, tick: int, brains: list, ids: list[int]) -> list[int]:
        """The record() of each controller the world records by shape (swarm.recording.records): the
        agents whose record went out (a tick without a number to show sends none)."""
        sent = []
        for brain, agent in zip(brains, ids, strict=True):
            if agent not in self.recorded or agent in self.quiet:
                continue
            record, why = record_of(brain)
            values = arena_proto.record_values(record, tick)
            if why is None and not values:
                continue  # nothing to show this tick
            message = None if why else arena_proto.record_message(tick, agent, values)
            if message is None:
                self.quiet.add(agent)
                why = why or f"it passed {arena_proto.MAX_RECORD_BYTES} bytes"
                print(f"swarm: the recording leaves out robot {agent}'s record(): {why}", file=sys.stderr, flush=True)
                continue
            self.session.put(self.keys.record(self.group), message, congestion_control=LOSSLESS)
            sent.append(agent)
        return sent

    def _send_plans(self, tick: int, agents: list[int]) -> None:
        """A controller's new plan goes to the world once, for the recording."""
        for agent in agents:
            # route(), not record(): a DFT robot's record stacks MBs of fields, a BG animat's walks its map
            route = getattr(self.brains[self.slot_of[agent]], "route", None)
            path = None if route is None else route()
            if path is None or len(path) < 2:
                continue
            key = (len(path), *np.asarray(path[0]).tolist(), *np.asarray(path[-1]).tolist())
            if self.sent_plans.get(agent) != key:
                self.sent_plans[agent] = key
                plan = arena_proto.plan_message(tick, agent, path)
                self.session.put(self.keys.plan(self.group), plan, congestion_control=LOSSLESS)


def give_back(brain, blob: bytes) -> bool:
    """Restore a controller from a saved memory.  One that cannot be decoded or
    restored leaves the controller as it was (False: the caller counts it)."""
    return restore_or_keep(brain, _decoded(brain, blob))


def _decoded(brain, blob: bytes | memoryview):
    """The memory in `blob`; its arrays are views of it for a controller that copies what it restores."""
    return memory_codec.decode(blob, views=getattr(brain, "restore_copies", False))


def restore_or_keep(brain, memory) -> bool:
    """`give_back` of a memory already decoded (a `Rejected` one restores nothing).  A controller whose
    restore() checks everything before it writes (`atomic_restore`) is trusted to change nothing when it
    raises; any other is rolled back to a copy of its state taken first."""
    if isinstance(memory, wire.Rejected):
        return False
    had = None if getattr(brain, "atomic_restore", False) else memory_codec.encode(brain.snapshot())
    try:  # `had` encoded: a snapshot may share the arrays restore() writes
        brain.restore(memory)
    except (KeyError, IndexError, TypeError, ValueError, AttributeError):
        if had is not None:
            brain.restore(memory_codec.decode(had))
        return False
    return True
