"""The agent process: K independent controllers around one zenoh session.

Transport, ids and retries live here, never in the controller: the runtime
joins (the world hands out ids, so identical processes need no configuration),
declares a liveliness token per agent, and for every observation runs the very
compiled step the in-process engine runs, then puts the mark write on the
marks key space and the action on its act key.
"""

from __future__ import annotations

import queue
import time
import uuid

import numpy as np

from agents.controllers import controller_kind, step_controller, warm_up
from agents.controllers.layout import A_MARK, MARK, MARK_NONE, new_action, new_memory
from swarm import protocol as proto
from swarm.bus import DEFAULT_ENDPOINT, open_client


class JoinRefused(RuntimeError):
    pass


class AgentRuntime:
    def __init__(self, run_id: str, controller: str, connect: str = DEFAULT_ENDPOINT, count: int = 1,
                 join_timeout: float = 60.0, idle_timeout: float = 120.0, null: bool = False):  # fmt: skip
        self.keys = proto.Keys(run_id)
        self.controller = controller
        self.kind = controller_kind(controller)
        self.null = null  # benchmark floor: answer STAY without running the controller
        warm_up()  # before joining: the world starts observing us as soon as we join
        self.idle_timeout = idle_timeout
        self.inbox: queue.Queue = queue.Queue()
        self.session = open_client(connect, timeout=join_timeout)
        self.agents: list[int] = []
        self.mem = new_memory(count)
        self.act = new_action()
        self._decls = []
        self.seed = 0
        self.params = np.zeros(1)
        for _ in range(count):
            self._join(join_timeout)
        self.slot_of = {agent: i for i, agent in enumerate(self.agents)}

    def _join(self, timeout: float) -> None:
        nonce = uuid.uuid4().hex
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            for reply in self.session.get(self.keys.join, payload=proto.join_request(nonce, controller=self.controller),
                                          timeout=2.0):  # fmt: skip
                if not reply.ok:
                    continue
                msg = proto.unpack(reply.ok.payload.to_bytes())
                if isinstance(msg, proto.Rejected):
                    continue
                if msg.get("type") == "refused":
                    raise JoinRefused(f"the world refused this agent: {msg.get('reason')}")
                if msg.get("type") == "welcome" and msg.get("nonce") == nonce:
                    agent = int(msg["agent"])
                    self.seed = int(msg["seed"])
                    self.params = np.array(msg["params"], dtype=np.float64)
                    self.agents.append(agent)
                    put = self.inbox.put
                    # Subscriber first: the world starts observing us when it sees the token.
                    self._decls.append(self.session.declare_subscriber(self.keys.obs(agent), put))
                    self._decls.append(self.session.liveliness().declare_token(self.keys.alive(agent)))
                    return
            time.sleep(0.2)
        raise TimeoutError(f"no world answered on {self.keys.join} within {timeout:.0f} s")

    def run(self) -> int:
        """Answer observations until the world says stop; returns ticks answered."""
        stopped: set[int] = set()
        answered = 0
        while len(stopped) < len(self.agents):
            try:
                batch = [self.inbox.get(timeout=self.idle_timeout)]
            except queue.Empty:
                raise TimeoutError(f"no observation for {self.idle_timeout:.0f} s; is the world gone?") from None
            while not self.inbox.empty():  # behind (real time): answer only the newest per agent
                batch.append(self.inbox.get_nowait())
            latest: dict[int, proto.Obs] = {}
            for sample in batch:
                msg = proto.parse_obs(sample.payload.to_bytes())
                if isinstance(msg, dict):  # stop
                    stopped.add(int(str(sample.key_expr).rsplit("/", 1)[1]))
                elif not isinstance(msg, proto.Rejected) and msg.agent in self.slot_of:
                    latest[msg.agent] = msg
            for msg in latest.values():
                if msg.agent not in stopped:
                    self._answer(msg)
                    answered += 1
        return answered

    def _answer(self, msg: proto.Obs) -> None:
        if self.null:
            self.session.put(self.keys.act(msg.agent), self._null_act(msg))
            return
        mem = self.mem[self.slot_of[msg.agent]]
        step_controller(self.kind, msg.pi, msg.pf, mem, self.act, self.params, np.int64(self.seed), msg.agent,
                        msg.tick)  # fmt: skip
        value = int(self.act[A_MARK])
        marked = bool(value != MARK_NONE and value < msg.pi[MARK])  # a write that changes nothing is not sent
        if marked:
            self.session.put(self.keys.mark(msg.cell), proto.mark_write(msg.tick, msg.agent, value))
        self.session.put(self.keys.act(msg.agent), proto.action(msg.tick, msg.agent, self.act, marked))

    def _null_act(self, msg: proto.Obs) -> bytes:
        self.act[:] = 0
        self.act[0] = 4  # STAY
        return proto.action(msg.tick, msg.agent, self.act, False)

    def close(self) -> None:
        for d in self._decls:
            d.undeclare()
        self.session.close()
