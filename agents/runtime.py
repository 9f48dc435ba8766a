"""The agent process: K independent controllers around one zenoh session.

Transport, ids and retries live here, never in the controller: the runtime
joins (the world hands out ids, so identical processes need no configuration),
declares a liveliness token per agent, and for every observation runs the very
step the in-process engine runs, then sends the actions on its act key.  What
a family's controllers are and how their messages look is the subclass's:
`GridAgentRuntime` (below) and `agents.arena_runtime.ArenaAgentRuntime`.
"""

from __future__ import annotations

import threading
import time
import uuid

import numpy as np

from agents.controllers.arena import ARENA_CONTROLLERS
from swarm.core import kernels, wire
from swarm.core.bus import DEFAULT_ENDPOINT, open_client
from swarm.core.errors import RunError
from swarm.monitor import world_info
from world_server.grid.face import wire as proto
from world_server.grid.face.layout import controller_kind, new_memory


class JoinRefused(RunError):
    pass


def load_step():
    """(`envelope.answer_message`, `dispatch.answer_rows`): the ahead-of-time build's
    when it exists (no numba in this process), else the JIT's (compiled or loaded
    from the cache now)."""
    built = kernels.load("answer_message"), kernels.load("answer_rows")
    if None not in built:
        return built
    from agents.controllers.dispatch import answer_rows, warm_up
    from agents.controllers.envelope import answer_message

    warm_up()
    return answer_message, answer_rows


class AgentRuntime:
    family = ""

    def __init__(self, run_id: str, controller: str, connect: str = DEFAULT_ENDPOINT, count: int = 1,
                 join_timeout: float = 60.0, idle_timeout: float = 120.0, null: bool = False,
                 rejoin_after: float = 5.0):  # fmt: skip
        self.keys = wire.Keys(run_id)
        self.controller = controller
        self.null = null  # benchmark floor: answer without running the controller
        self._prepare(count)  # before joining: the world observes us at once
        self.idle_timeout = idle_timeout
        self.session = open_client(connect, timeout=join_timeout)
        self.group = uuid.uuid4().hex  # this process: its agents' messages travel together
        # Subscribed before joining: the world starts observing an agent as soon as it sees its token.
        # A FIFO channel read by the main thread: no Python callback thread between zenoh and the step.
        self.inbox = self.session.declare_subscriber(self.keys.obs(self.group))
        self.act_publisher = self.session.declare_publisher(self.keys.act(self.group))
        self._decls = [self.inbox, self.act_publisher]
        self._heard = time.monotonic()  # when the last observation came
        self._closed = threading.Event()
        self.lockstep = False  # the world's mode, from its welcome
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

    def _answer_raw(self, raw: bytes) -> int | None:
        """Answer a plain observation straight from its bytes (agents answered),
        or None: the message goes through `_parse` (families without a fast path)."""
        return None

    def _restore(self, memory) -> None:
        """A resumed world hands back the controllers' memory of its saved tick."""

    # -------------------------------------------------------------- transport

    def _join(self, timeout: float, slot: int) -> int:
        """Ask the world for an id; returns it once our liveliness token is declared."""
        nonce = uuid.uuid4().hex
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            request = wire.join_request(nonce, self.group, family=self.family, controller=self.controller)
            for reply in self.session.get(self.keys.join, payload=request, timeout=2.0):
                if not reply.ok:
                    continue
                data, reply = reply.ok.payload.to_bytes(), None  # zenoh's copy goes: a welcome may carry MBs
                msg, data = wire.unpack(data, wire.MAX_WELCOME_BYTES), None
                if isinstance(msg, wire.Rejected):
                    continue
                if msg.get("type") == "refused":
                    raise JoinRefused(f"the world refused this agent: {msg.get('reason')}")
                if msg.get("type") == "welcome" and msg.get("nonce") == nonce:
                    agent = int(msg["agent"])
                    self.lockstep = bool(msg.get("lockstep"))
                    self._welcomed(slot, agent, msg)
                    self.tokens[agent] = self.session.liveliness().declare_token(self.keys.alive(agent))
                    return agent
            time.sleep(0.2)
        raise TimeoutError(f"no world answered on {self.keys.join} within {timeout:.0f} s")

    def run(self) -> int:
        """Answer observations until the world says stop; returns agent-steps answered.
        The usual message, one plain observation, goes the short way: a few
        Python operations and one compiled call, and nothing else, since at
        100 processes on 2 cores each object an agent touches is cold when
        its turn comes (dropping a numpy slice, an `item` and a `try_recv`
        gained some 4% of a tick, issue 12).  Anything else, or in real time
        more than one message waiting, goes through `_answer_batch`."""
        answered = 0
        self._heard = time.monotonic()
        threading.Thread(target=self._wake_when_quiet, name="swarm-wake", daemon=True).start()
        recv, try_recv, answer_raw, monotonic = self.inbox.recv, self.inbox.try_recv, self._answer_raw, time.monotonic
        lockstep = self.lockstep  # the world waits for every answer: never more than one observation waiting
        while True:
            raw = recv().payload.to_bytes()  # and zenoh's copy goes at once (issue 12's 80 MB)
            if lockstep or (more := try_recv()) is None:
                if (fast := answer_raw(raw)) is not None:
                    answered += fast
                    self._heard = monotonic()
                    continue
                batch = [raw]
            else:  # behind (real time): answer only the newest
                batch = [raw, more]
                while (more := try_recv()) is not None:
                    batch.append(more)
            stop, steps = self._answer_batch(batch)
            answered += steps
            if stop:
                return answered

    def _answer_batch(self, batch: list) -> tuple[bool, int]:
        """Every message that came together, samples or their bytes, in order:
        a stop ends the run, memory handed back is restored, and only the
        newest observation is answered.  Returns (stop, agent-steps answered)."""
        latest, last = None, len(batch) - 1
        for i, item in enumerate(batch):
            tried = isinstance(item, bytes)  # bytes: `run` has read them (and tried the short way if last)
            raw = item if tried else item.payload.to_bytes()
            batch[i] = item = None  # zenoh's copy goes now: memory handed back is MBs (issue 12's 80 MB)
            if i == last and not tried and (fast := self._answer_raw(raw)) is not None:  # a plain observation
                self._heard = time.monotonic()
                return False, fast  # older observations of the batch are superseded
            msg, raw = self._parse(raw), None  # and the bytes once parsed
            if isinstance(msg, dict):
                if msg.get("type") == "stop":
                    return True, 0
            elif isinstance(msg, wire.HandBack):
                self._heard = time.monotonic()
                self._restore(msg)
            elif not isinstance(msg, wire.Rejected):
                latest = msg
        if latest is not None:
            self._heard = time.monotonic()
            return False, self._answer(latest)
        if (quiet := time.monotonic() - self._heard) > self.idle_timeout:
            raise TimeoutError(f"no observation for {self.idle_timeout:.0f} s; is the world gone?")
        if quiet >= self.rejoin_after:
            self._rejoin_if_dropped()
        return False, 0

    def _wake_when_quiet(self) -> None:
        """The main thread blocks in the channel: when no observation has come
        for `rejoin_after`, wake it with a message to ourselves so that it can
        check our membership (and give up after `idle_timeout`)."""
        wake = wire.pack({"type": "wake"})
        while not self._closed.wait(self.rejoin_after / 2):
            if time.monotonic() - self._heard >= self.rejoin_after:
                try:
                    self.session.put(self.keys.obs(self.group), wake)
                except Exception:  # the session is closing
                    return

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
        self._closed.set()
        for d in [*self._decls, *self.tokens.values()]:
            d.undeclare()
        self.session.close()


class GridAgentRuntime(AgentRuntime):
    """Grid controllers: one compiled call checks and steps the whole batch
    (`dispatch.answer_rows`); memory per agent."""

    family = wire.FAMILY_GRID

    def _prepare(self, count: int) -> None:
        self.kind = controller_kind(self.controller)
        self.answer_message, self.answer_rows = load_step()
        self.mem = new_memory(count)
        self.rows = np.zeros((count, proto.ACT_ROW), dtype=np.int64)  # the action rows, reused
        # The action message's bytes and the call's info (rows, any mark write, tick): the compiled call
        # writes them through numpy views, the short way reads them without numpy (a slice, a memoryview).
        self.out_bytes = bytearray(proto.ENVELOPE + count * proto.ACT_ROW * 8)
        self.out = np.frombuffer(self.out_bytes, dtype=np.uint8)
        info = bytearray(3 * 8)
        self.info, self.rows_written = np.frombuffer(info, dtype=np.int64), memoryview(info).cast("q")
        self.slot_table = np.full(0, -1, dtype=np.int64)  # agent id -> its slot (memory row), -1: not ours
        self.seed = 0
        self.params = np.zeros(1)

    def _welcomed(self, slot: int, agent: int, msg: dict) -> None:
        self.seed = int(msg["seed"])  # a Python int: no numpy scalar to convert at every call
        self.params = np.array(msg["params"], dtype=np.float64)
        # the slot's memory: fresh, or where a resumed run's agent was saved (this one takes it over)
        self.mem[slot] = msg.get("memory", new_memory(1)[0])
        self.slot_table[self.slot_table == slot] = -1
        if agent >= len(self.slot_table):
            self.slot_table = np.concatenate([self.slot_table, np.full(agent + 1 - len(self.slot_table), -1)])
        self.slot_table[agent] = slot

    def _parse(self, data: bytes):
        return proto.obs_blocks(data)

    def _answer_raw(self, raw: bytes) -> int | None:
        """Step every agent of ours in the observation and send the action
        message, envelope and all from one compiled call (`envelope`); mark
        writes ride the action rows."""
        size = self.answer_message(self.kind, raw, self.mem, self.slot_table, self.rows,
                                   self.params, self.seed, self.null, self.out, self.info)  # fmt: skip
        if size == proto.NOT_PLAIN:
            return None
        if size < 0:
            return 0  # a malformed observation: not answered (the world counts the miss)
        self.act_publisher.put(self.out_bytes[:size])
        return self.rows_written[0]

    def _restore(self, memory: proto.Memory) -> None:
        for agent, *words in memory.rows.tolist():
            if (slot := self.slot_of.get(agent)) is not None:
                self.mem[slot] = words

    def _answer(self, obs: proto.ObsBlocks) -> int:
        """An observation in another layout than our world's (its keys in another
        order, say): the same step through the parsed blocks."""
        n = self.answer_rows(self.kind, np.frombuffer(obs.ints, "<i8"), np.frombuffer(obs.pf, "<f8"), self.mem,
                             self.slot_table, self.rows, self.params, self.seed, obs.tick, self.null)  # fmt: skip
        if n < 0:
            return 0  # a malformed observation: not answered (the world counts the miss)
        self.act_publisher.put(proto.pack_actions(obs.tick, self.rows[:n]))
        return n


def make_runtime(run_id: str, controller: str, connect: str = DEFAULT_ENDPOINT, count: int = 1,
                 **kw) -> AgentRuntime:  # fmt: skip
    """The runtime of the controller's family."""
    if controller in ARENA_CONTROLLERS:
        from agents.arena_runtime import ArenaAgentRuntime

        return ArenaAgentRuntime(run_id, controller, connect, count, **kw)
    return GridAgentRuntime(run_id, controller, connect, count, **kw)
