"""The agent process: K independent controllers around one zenoh session.

Transport, ids and retries live here, never in the controller: the runtime
joins (the world hands out ids, so identical processes need no configuration),
declares a liveliness token per agent, and for every observation runs the very
step the in-process engine runs, then sends the actions on its act key.  What
a family's controllers are and how their messages look is the subclass's:
`GridAgentRuntime` (below) and `agents.arena_runtime.ArenaAgentRuntime`.
"""

from __future__ import annotations

import queue
import time
import uuid

import numpy as np

from agents.controllers import aot
from agents.controllers.arena import ARENA_CONTROLLERS
from agents.controllers.layout import A_MARK, MARK, MARK_NONE, controller_kind, new_action, new_memory
from swarm import protocol as proto
from swarm.bus import DEFAULT_ENDPOINT, open_client
from swarm.monitor import world_info


class JoinRefused(RuntimeError):
    pass


def load_step():
    """The ahead-of-time build of the controller step when it exists (no numba
    in this process), else the JIT's (compiled or loaded from the cache now)."""
    step = aot.load()
    if step is None:
        from agents.controllers.dispatch import step_controller, warm_up

        warm_up()
        step = step_controller
    return step


class AgentRuntime:
    family = ""

    def __init__(self, run_id: str, controller: str, connect: str = DEFAULT_ENDPOINT, count: int = 1,
                 join_timeout: float = 60.0, idle_timeout: float = 120.0, null: bool = False,
                 rejoin_after: float = 5.0):  # fmt: skip
        self.keys = proto.Keys(run_id)
        self.controller = controller
        self.null = null  # benchmark floor: answer without running the controller
        self._prepare(count)  # before joining: the world observes us at once
        self.idle_timeout = idle_timeout
        self.inbox: queue.Queue = queue.Queue()
        self.session = open_client(connect, timeout=join_timeout)
        self.group = uuid.uuid4().hex  # this process: its agents' messages travel together
        # Subscribed before joining: the world starts observing an agent as soon as it sees its token.
        self._decls = [self.session.declare_subscriber(self.keys.obs(self.group), self.inbox.put)]
        self.agents: list[int] = []  # our agents' ids, by slot
        self.tokens: dict[int, object] = {}  # agent id -> its liveliness token
        self.rejoin_after = rejoin_after
        for slot in range(count):
            self.agents.append(self._join(join_timeout, slot))
        self.slot_of = {agent: i for i, agent in enumerate(self.agents)}

    # ------------------------------------------------------- hooks of a family

    def _prepare(self, count: int) -> None:
        """Load the controllers' code before joining."""

    def _welcomed(self, slot: int, agent: int, msg: dict) -> None:
        """The world gave `slot` the id `agent`: start its controller afresh."""
        raise NotImplementedError

    def _parse(self, data: bytes):
        raise NotImplementedError

    def _answer(self, obs) -> int:
        raise NotImplementedError

    # -------------------------------------------------------------- transport

    def _join(self, timeout: float, slot: int) -> int:
        """Ask the world for an id; returns it once our liveliness token is declared."""
        nonce = uuid.uuid4().hex
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            request = proto.join_request(nonce, self.group, family=self.family, controller=self.controller)
            for reply in self.session.get(self.keys.join, payload=request, timeout=2.0):
                if not reply.ok:
                    continue
                msg = proto.unpack(reply.ok.payload.to_bytes(), proto.MAX_WELCOME_BYTES)
                if isinstance(msg, proto.Rejected):
                    continue
                if msg.get("type") == "refused":
                    raise JoinRefused(f"the world refused this agent: {msg.get('reason')}")
                if msg.get("type") == "welcome" and msg.get("nonce") == nonce:
                    agent = int(msg["agent"])
                    self._welcomed(slot, agent, msg)
                    self.tokens[agent] = self.session.liveliness().declare_token(self.keys.alive(agent))
                    return agent
            time.sleep(0.2)
        raise TimeoutError(f"no world answered on {self.keys.join} within {timeout:.0f} s")

    def run(self) -> int:
        """Answer observations until the world says stop; returns agent-steps answered."""
        answered = 0
        heard = time.monotonic()
        while True:
            try:
                batch = [self.inbox.get(timeout=self.rejoin_after)]
            except queue.Empty:
                if time.monotonic() - heard > self.idle_timeout:
                    raise TimeoutError(f"no observation for {self.idle_timeout:.0f} s; is the world gone?") from None
                self._rejoin_if_dropped()
                continue
            heard = time.monotonic()
            while not self.inbox.empty():  # behind (real time): answer only the newest
                batch.append(self.inbox.get_nowait())
            latest = None
            for sample in batch:
                msg = self._parse(sample.payload.to_bytes())
                if isinstance(msg, dict):  # stop
                    return answered
                if not isinstance(msg, proto.Rejected):
                    latest = msg
            if latest is not None:
                answered += self._answer(latest)

    def _rejoin_if_dropped(self) -> None:
        """Quiet for a while: if the world has declared some of our agents lost
        (a cut link, a stall), join again for them as new agents with fresh
        controllers.  A world that does not answer, or that simply has not
        started, is left alone."""
        try:
            info = world_info(self.session, self.keys)
        except Exception:  # zenoh errors while the link is down: try again later
            return
        if info is None or info.get("ended"):
            return
        members = set(info.get("members", []))
        for slot, agent in enumerate(self.agents):
            if agent in members:
                continue
            if (token := self.tokens.pop(agent, None)) is not None:
                token.undeclare()
            try:
                self.agents[slot] = self._join(5.0, slot)
            except TimeoutError:
                break
        self.slot_of = {agent: i for i, agent in enumerate(self.agents)}

    def close(self) -> None:
        for d in [*self._decls, *self.tokens.values()]:
            d.undeclare()
        self.session.close()


class GridAgentRuntime(AgentRuntime):
    """Grid controllers: one compiled step over flat arrays, memory per agent."""

    family = proto.FAMILY_GRID

    def _prepare(self, count: int) -> None:
        self.kind = controller_kind(self.controller)
        self.step = None if self.null else load_step()
        self.mem = new_memory(count)
        self.act = new_action()
        self.seed = 0
        self.params = np.zeros(1)

    def _welcomed(self, slot: int, agent: int, msg: dict) -> None:
        self.seed = int(msg["seed"])
        self.params = np.array(msg["params"], dtype=np.float64)
        self.mem[slot] = new_memory(1)[0]

    def _parse(self, data: bytes):
        return proto.parse_obs(data)

    def _answer(self, obs: proto.Obs) -> int:
        """Step every agent of ours in the batch; one mark message, one action message."""
        acts = np.zeros((len(obs.agents), self.act.shape[0]), dtype=np.int64)
        agents, marked, mark_agents, mark_cells, mark_values = [], [], [], [], []
        seed = np.int64(self.seed)
        for i, agent in enumerate(obs.agents.tolist()):
            slot = self.slot_of.get(agent)
            if slot is None:
                continue
            act = acts[len(agents)]
            if self.null:
                act[0] = 4  # STAY
            else:
                self.step(self.kind, obs.pi[i], obs.pf[i], self.mem[slot], act, self.params, seed, agent, obs.tick)
            value = int(act[A_MARK])
            lowers = value != MARK_NONE and value < obs.pi[i, MARK]  # a write that changes nothing is not sent
            if lowers:
                mark_agents.append(agent)
                mark_cells.append(int(obs.cells[i]))
                mark_values.append(value)
            agents.append(agent)
            marked.append(lowers)
        if mark_agents:
            self.session.put(
                self.keys.mark(self.group), proto.mark_writes(obs.tick, mark_agents, mark_cells, mark_values)
            )
        self.session.put(self.keys.act(self.group), proto.actions(obs.tick, agents, acts[: len(agents)], marked))
        return len(agents)


def make_runtime(run_id: str, controller: str, connect: str = DEFAULT_ENDPOINT, count: int = 1,
                 **kw) -> AgentRuntime:  # fmt: skip
    """The runtime of the controller's family."""
    if controller in ARENA_CONTROLLERS:
        from agents.arena_runtime import ArenaAgentRuntime

        return ArenaAgentRuntime(run_id, controller, connect, count, **kw)
    return GridAgentRuntime(run_id, controller, connect, count, **kw)
