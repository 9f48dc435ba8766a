"""The agent process: K independent controllers around one zenoh session.

Transport, ids and retries live here, never in the controller: the runtime
joins (the world hands out ids, so identical processes need no configuration),
declares a liveliness token per agent, and for every observation runs the very
step the in-process engine runs, then sends the actions on its act key.  What
a family's controllers are and how their messages look is the subclass's:
`agents.grid_runtime.GridAgentRuntime` and `agents.arena_runtime.ArenaAgentRuntime`
(`agents.runtimes.make_runtime` picks one).
"""

from __future__ import annotations

import json
import os
import threading
import time
import uuid
from collections import Counter

from swarm.core import wire
from swarm.core.bus import DEFAULT_ENDPOINT, LOSSLESS, open_client
from swarm.core.credentials import Identity, own_group
from swarm.core.errors import RunError
from swarm.core.wire import world_info


class JoinRefused(RunError):
    pass


class AgentRuntime:
    family = ""

    def __init__(self, run_id: str, controller: str, connect: str = DEFAULT_ENDPOINT, count: int = 1,
                 join_timeout: float = 60.0, idle_timeout: float = 120.0, null: bool = False,
                 rejoin_after: float = 5.0, on_error: str = "idle", ids_file: str | None = None,
                 identity: Identity | None = None):  # fmt: skip
        self.keys = wire.Keys(run_id)
        self.rejected: Counter[str] = Counter()  # messages to us refused, by reason: said when the process ends
        self.ids_file = ids_file  # where our agents' ids go once joined (`swarm up` names them if we die)
        self.controller = controller
        self.on_error = on_error  # a controller that raises: its robot holds still, or the process stops
        self.null = null  # benchmark floor: answer without running the controller
        self._prepare(count)  # before joining: the world observes us at once
        self.idle_timeout = idle_timeout
        self.session = open_client(connect, timeout=join_timeout, identity=identity)
        # this process: its agents' messages travel together (a secure run's router lets it put on its own only)
        self.group = own_group(identity) or uuid.uuid4().hex
        # Subscribed before joining: the world starts observing an agent as soon as it sees its token.
        # A FIFO channel read by the main thread: no Python callback thread between zenoh and the step.
        self.inbox = self.session.declare_subscriber(self.keys.obs(self.group))
        self.act_publisher = self.session.declare_publisher(self.keys.act(self.group), congestion_control=LOSSLESS)
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
        self._tell_ids()

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
                msg, data = wire.parse_welcome(data, nonce), None
                if isinstance(msg, wire.Rejected):
                    self.rejected[f"welcome: {msg.reason}"] += 1
                    continue
                if msg["type"] == "refused":
                    raise JoinRefused(f"the world refused this agent: {msg['reason']}")
                agent = msg["agent"]
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
        gained some 4% of a tick).  Anything else, or in real time
        more than one message waiting, goes through `_answer_batch`."""
        answered = 0
        self._heard = time.monotonic()
        threading.Thread(target=self._wake_when_quiet, name="swarm-wake", daemon=True).start()
        recv, try_recv, answer_raw, monotonic = self.inbox.recv, self.inbox.try_recv, self._answer_raw, time.monotonic
        lockstep = self.lockstep  # the world waits for every answer: never more than one observation waiting
        while True:
            raw = recv().payload.to_bytes()  # and zenoh's copy goes at once (an agent process's 80 MB budget)
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
            batch[i] = item = None  # zenoh's copy goes now: memory handed back is MBs (an agent process's 80 MB budget)
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
            elif isinstance(msg, wire.Rejected):
                self.rejected[f"obs: {msg.reason}"] += 1
            else:
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
        self._tell_ids()

    def rejections(self) -> Counter[str]:
        """What this process refused, by reason: malformed messages, and a family's refused parts."""
        return Counter(self.rejected)

    def rejections_line(self) -> str | None:
        """One line for the process's standard error when it ends (None: nothing was refused)."""
        counts = self.rejections()
        if not counts:
            return None
        reasons = "; ".join(f"{reason}: {n}" for reason, n in sorted(counts.items()))
        return f"swarm: agent process refused {counts.total()} messages or parts of them ({reasons})"

    def _tell_ids(self) -> None:
        """Our agents' ids, as a JSON list in `ids_file` (replaced whole): the launcher reads them
        to say which agents a process ran when it dies, and whether it had joined at all."""
        if self.ids_file:
            part = f"{self.ids_file}.part"
            with open(part, "w") as f:
                json.dump(self.agents, f)
            os.replace(part, self.ids_file)

    def close(self) -> None:
        self._closed.set()
        for d in [*self._decls, *self.tokens.values()]:
            d.undeclare()
        self.session.close()
