"""The flooding clients of `swarm bench flood`, each its own process with its own zenoh session, putting
at a set rate (or as fast as it can) until told to stop:

    garbage   random bytes on the world's keys under names no agent process has (act, plans, records,
              marks), and garbage queries on join, info and marks (a tenth of its messages)
    forged    well-formed actions on every agent process's own key (learnt from its observations), for
              the tick before the current one or for one the run never comes to, and ones cut short
    own       what an agent process flooding its own key sends: its answer to the current observation,
              put again and again, and garbage between the copies

None of them forges an action for a tick the world plays: on an unsecured run that is impersonation,
which the secure runs' access rules (swarm/core/acl.py) keep off an agent process's keys.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import time

import numpy as np
import zenoh

from swarm.core import wire
from swarm.core.bus import open_client
from world_server.arena.face import wire as arena_proto
from world_server.grid.face import wire as grid_proto

BATCH = 50  # messages between two looks at the clock and the stop flag
KINDS = ("garbage", "forged", "own")


class _Pace:
    """A client's count of messages sent, shared with the bench, and its rate (0: as fast as it can)."""

    def __init__(self, sent, rate: float, stop):
        self.count, self.rate, self.stop = sent, rate, stop
        self.started = self._zero = 0.0  # when it began to send; when it would have begun at its rate

    def sent(self, n: int) -> bool:
        """Count `n` more; wait while ahead of the rate (a client that had nothing to flood yet does not
        make up for it).  False once the client is to stop."""
        if not self.started:
            self.started = self._zero = time.monotonic()
        with self.count.get_lock():
            self.count.value += n
            count = self.count.value
        if not self.rate:
            return not self.stop.is_set()
        ahead = self._zero + count / self.rate - time.monotonic()
        if ahead < -1.0:
            self._zero -= ahead + 1.0
        return not self.stop.wait(ahead) if ahead > 0 else not self.stop.is_set()


def flood(kind: str, endpoint: str, run_id: str, family: str, seed: int, rate: float, nice: int, stop, ready,
          sent, seconds) -> None:  # fmt: skip
    """One flooding client: `kind` of KINDS, `rate` messages a second (0: as fast as it can), at `nice`;
    `ready` (a shared semaphore) is released once it listens and floods, `sent` (a shared integer) counts
    its puts and queries, `seconds` (a shared float) how long it flooded.  It connects and subscribes at
    the bench's priority, so that on a loaded machine it hears the run from its first observation, and
    floods at `nice`."""
    session = open_client(endpoint, timeout=120)

    def flooding() -> None:
        ready.release()
        for thread in os.listdir("/proc/self/task"):  # niceness is per thread on Linux: zenoh's are running
            os.setpriority(os.PRIO_PROCESS, int(thread), os.getpriority(os.PRIO_PROCESS, int(thread)) + nice)

    pace = _Pace(sent, rate, stop)
    keys = wire.Keys(run_id)
    rng = np.random.default_rng(seed)
    garbage = [rng.bytes(int(n)) for n in rng.integers(1, 160, 64)]
    try:
        if kind == "garbage":
            _garbage(session, keys, garbage, pace, flooding)
        elif kind == "forged":
            _forged(session, keys, family, garbage, pace, flooding)
        else:
            _own(session, keys, garbage, pace, flooding)
    finally:
        seconds.value = time.monotonic() - pace.started if pace.started else 0.0
        session.close()


def _garbage(session, keys: wire.Keys, garbage: list[bytes], pace: _Pace, flooding) -> None:
    targets = [keys.act("stranger"), keys.plan("stranger"), keys.record("stranger"), keys.mark("stranger")]
    pubs = [session.declare_publisher(k) for k in targets]
    flooding()
    k = 0
    while True:
        for _ in range(BATCH):
            pubs[k % len(pubs)].put(garbage[k % len(garbage)])
            k += 1
        for key in (keys.join, keys.info, keys.marks):  # not waiting for any reply
            session.get(key, lambda _reply: None, payload=garbage[k % len(garbage)], timeout=1.0)
        if not pace.sent(BATCH + 3):
            return


class _Heard:
    """What the flooding client hears of the agent processes: the tick of each one's newest observation,
    and its answer to it.  Read by the flooding loop (`poll`) from ring channels, which drop old samples
    when it falls behind: a subscriber that stops reading would hold a lock-step world's tick, whose
    messages wait for room on their links (swarm.core.bus.LOSSLESS)."""

    def __init__(self, session, keys: wire.Keys):
        self.tick: dict[str, int] = {}
        self.answer: dict[str, bytes] = {}
        self._obs = session.declare_subscriber(keys.obs("*"), zenoh.handlers.RingChannel(64))
        self._act = session.declare_subscriber(keys.act("*"), zenoh.handlers.RingChannel(64))

    def poll(self) -> None:
        """Take what came since the last poll: observations first, then the answers to them."""
        while (sample := self._obs.try_recv()) is not None:
            if (tick := wire.peek_tick(sample.payload.to_bytes())) is not None:
                self.tick[str(sample.key_expr).rsplit("/", 1)[1]] = tick
        while (sample := self._act.try_recv()) is not None:
            group, raw = str(sample.key_expr).rsplit("/", 1)[1], sample.payload.to_bytes()
            if group in self.tick and wire.peek_tick(raw) == self.tick[group]:  # its answer (or a copy of it)
                self.answer[group] = raw


def _forgeries(family: str, tick: int, garbage: bytes) -> list[bytes]:
    """Actions for agents 0..3 for the tick before `tick` and for one the run never comes to, and one cut
    short.  (One for a tick the world plays later would be impersonation: the world cannot tell it from
    the agent process's own answer, if it came first.)"""
    agents = [0, 1, 2, 3]
    if family == wire.FAMILY_GRID:
        stay = np.zeros((len(agents), 8), np.int64)
        make = lambda t: grid_proto.actions(t, agents, stay, [False] * len(agents))  # noqa: E731
    else:
        make = lambda t: arena_proto.actions(t, agents, np.full((len(agents), 2), 0.1))  # noqa: E731
    past, never = make(tick - 1), make(2**40)  # at tick 0, -1: before the run
    return [past, never, past[: len(past) // 2] + garbage]


def _on_their_keys(session, keys: wire.Keys, pace: _Pace, heard: _Heard, what: str, messages) -> None:
    """Put `messages(value, k)` on each agent process's action key in turn, for each `group: value` of
    `heard.<what>` (what was heard of it so far)."""
    pubs: dict[str, object] = {}
    k = 0
    while True:
        heard.poll()
        values = getattr(heard, what)
        for group, value in list(values.items()):
            pub = pubs.get(group) or pubs.setdefault(group, session.declare_publisher(keys.act(group)))
            for _ in range(BATCH):
                pub.put(messages(value, k))
                k += 1
            if not pace.sent(BATCH):
                return
        if not values and pace.stop.wait(0.05):
            return


def _forged(session, keys: wire.Keys, family: str, garbage: list[bytes], pace: _Pace, flooding) -> None:
    made: dict[int, list[bytes]] = {}

    def forged(tick: int, k: int) -> bytes:
        if tick not in made:
            made.clear()
            made[tick] = _forgeries(family, tick, garbage[tick % len(garbage)])
        return made[tick][k % 3]

    heard = _Heard(session, keys)
    flooding()
    _on_their_keys(session, keys, pace, heard, "tick", forged)


def _own(session, keys: wire.Keys, garbage: list[bytes], pace: _Pace, flooding) -> None:
    def again(answer: bytes, k: int) -> bytes:
        return answer if k % 2 else garbage[k % len(garbage)]

    heard = _Heard(session, keys)
    flooding()
    _on_their_keys(session, keys, pace, heard, "answer", again)


class Floods:
    """The flooding clients of one run, started before it (they wait for its router) and stopped after it:
    `rate` messages a second of all together (0: each as fast as it can), each at niceness `nice`."""

    def __init__(self, endpoint: str, run_id: str, family: str, kinds=KINDS, rate: float = 0.0, nice: int = 0):
        ctx = mp.get_context("spawn")
        self.stop, self.ready = ctx.Event(), ctx.Semaphore(0)
        self.sent = {kind: ctx.Value("q", 0) for kind in kinds}
        self.seconds = {kind: ctx.Value("d", 0.0) for kind in kinds}
        each = rate / max(1, len(kinds))
        self.procs = [ctx.Process(target=flood, daemon=True, args=(kind, endpoint, run_id, family, i, each, nice,
                                                                   self.stop, self.ready, self.sent[kind],
                                                                   self.seconds[kind]))
                      for i, kind in enumerate(kinds)]  # fmt: skip

    def __enter__(self) -> Floods:
        for p in self.procs:
            p.start()
        return self

    def wait_ready(self, timeout: float) -> None:
        """Until every client listens and floods (a router must be up for them to reach)."""
        deadline = time.monotonic() + timeout
        for _ in self.procs:
            if not self.ready.acquire(timeout=max(0.0, deadline - time.monotonic())):
                raise TimeoutError(f"the flooding clients did not start within {timeout:g} s")

    def __exit__(self, *exc) -> None:
        self.stop.set()
        for p in self.procs:
            p.join(10)
            if p.is_alive():
                p.kill()
                p.join(5)

    def counts(self) -> dict[str, int]:
        """Each client's puts and queries."""
        return {kind: int(v.value) for kind, v in self.sent.items()}

    def rate(self) -> float:
        """Puts and queries per second, of all clients together (each from its first put)."""
        return sum(v.value / max(self.seconds[kind].value, 1e-9) for kind, v in self.sent.items())
