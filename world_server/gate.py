"""The world's door: every message and query is let in against its sender's budget on zenoh's thread,
before anything decodes or queues it, so a client that floods the world spends its own budget and is
counted, while the tick goes on with what the budgets let through.

A sender is the agent process a key names (`act/<group>`, `plans/<group>`, ...) once it has joined;
every other client of a key space is one "stranger", and so is everyone who queries.  Each sender has
a token bucket per key space and class of message, refilled each tick or each second (`Allowance`);
a message that finds its bucket empty is dropped and counted as "<space>: over budget".  The class
comes from a look at the message's first bytes, not a decode: an agent process's message for a tick
being played ("now") draws on another bucket than its other ones ("other"), so its answer is never
behind a flood of old, future or garbage messages on its key; and a join request on another bucket
than garbage joins.  A client that floods an agent process's key with the current tick's number has
read that process's observations and could as well answer in its place: on a secure run the router's
access rules (swarm/core/acl.py) keep it off the key.

The budgets are several times what agents send (one action per process and tick, a plan and a record
per agent and tick, a join per agent), so a run that is not flooded never meets them and stays exactly
as it was.  Queries cost the world a reply (a summary, the marks), so their budgets are small.  Liveliness
tokens (`let_alive`) have a budget of their own, split as joins are: the tokens the world waits for, and
the rest.

Every message of a flood holds the world's interpreter lock for as long as its callback runs, and the
world's thread waits for that lock: a sender whose buckets are empty until the next tick (or the next
token's time) is dropped without the lock, without copying its message, and counted by an atomic step.
"""

from __future__ import annotations

import itertools
import math
import threading
import time
from collections.abc import Callable, Container
from dataclasses import dataclass

from swarm.core import wire

NOW, OTHER = "now", "other"
PUTS = ("act", "plan", "record", "mark")  # subscribed key spaces: the sender is the key's last part
QUERIES = ("join", "info", "marks query", "shared query")  # queryables: every querier is a stranger
ALIVE = "alive"  # liveliness tokens appearing and going: any client may declare one on any agent's key
LAG = {"plan": 1, "record": 1}  # a plan comes after its action: the world may be a tick on by then
JOIN_HEAD = b"\xa4type\xa4join"  # what a join request holds in its first bytes (swarm.core.wire.join_request)


@dataclass(frozen=True)
class Allowance:
    """A token bucket: `burst` tokens at first and at most, `per_tick` more each tick the world plays and
    `per_second` more each second (for senders whose traffic does not follow the ticks)."""

    burst: float
    per_tick: float = 0.0
    per_second: float = 0.0


STRANGERS = Allowance(64, per_second=50)  # puts on keys no agent process has: garbage, or a client of a test
ASKING = Allowance(16, per_second=5)  # queries: a person's `swarm status`, a client reading a key space


def allowances(agents: int) -> dict[tuple[str, str], Allowance]:
    """The budgets of a run of `agents` agents, by (key space, class); the other puts get `STRANGERS`,
    the other queries `ASKING`.  An agent process sends one action per tick, a plan and a record per
    agent and tick (at most all the run's agents), a join per agent, and asks for the info when it has
    heard nothing for a while (every few seconds at most)."""
    per_agent = Allowance(2 * agents + 16, per_tick=2 * agents + 2)
    few = Allowance(16, per_tick=1)
    return {
        ("act", NOW): Allowance(8, per_tick=2), ("act", OTHER): few,
        ("plan", NOW): per_agent, ("plan", OTHER): few, ("record", NOW): per_agent, ("record", OTHER): few,
        ("join", NOW): Allowance(2 * agents + 64, per_second=50),
        ("info", OTHER): Allowance(2 * agents + 16, per_second=agents + 5),
        (ALIVE, NOW): Allowance(2 * agents + 64, per_second=50), (ALIVE, OTHER): STRANGERS,
    }  # fmt: skip


class Bucket:
    """One sender's tokens for one key space and class, and the messages it dropped (an atomic counter,
    stepped without the lock)."""

    __slots__ = ("all", "allowance", "at", "closed_at", "counted", "drops", "reads", "reason", "reopens", "tick",
                 "tokens")  # fmt: skip

    def __init__(self, allowance: Allowance, reason: str, tick: int, at: float, drops_of_all):
        self.allowance, self.reason = allowance, reason
        self.tokens, self.tick, self.at = float(allowance.burst), tick, at
        self.closed_at, self.reopens = -1, 0.0  # empty at this tick, until this time (`closed`)
        self.drops, self.reads, self.counted = itertools.count(), 0, 0
        self.all = drops_of_all  # the gate's count of every bucket's drops, so the world looks at one when none

    def drop(self) -> None:
        """Count a message dropped (each `next` is one step, whatever thread takes it)."""
        next(self.drops)
        next(self.all)

    def closed(self, tick: int, clock: Callable[[], float]) -> bool:
        """Surely empty, read without the lock: found empty at this tick, and its next token not due yet."""
        return self.closed_at == tick and (self.reopens == math.inf or clock() < self.reopens)

    def empty(self, tick: int, clock: Callable[[], float]) -> bool:
        """Refilled for the ticks and the time since the last refill (the caller holds the gate's lock: the
        tick and the clock only go on), has the bucket no token?  When not, it is `closed` until the next
        tick or the next token's time."""
        a = self.allowance
        if tick > self.tick:
            self.tokens = min(a.burst, self.tokens + (tick - self.tick) * a.per_tick)
            self.tick = tick
        if a.per_second:
            now = clock()
            self.tokens = min(a.burst, self.tokens + (now - self.at) * a.per_second)
            self.at = now
        if self.tokens >= 1.0:
            return False
        self.closed_at = tick
        self.reopens = self.at + (1.0 - self.tokens) / a.per_second if a.per_second else math.inf
        return True

    def spend(self, tick: int, clock: Callable[[], float]) -> bool:
        """Take a token; False, counted, when there is none."""
        if self.empty(tick, clock):
            self.drop()
            return False
        self.tokens -= 1.0
        return True

    def take_dropped(self) -> int:
        """The messages dropped since the last call (each call steps the counter once more itself)."""
        total = next(self.drops) - self.reads
        self.reads += 1
        new, self.counted = total - self.counted, total
        return new


class Gate:
    """The budgets of one run, checked on zenoh's threads; the world's thread takes the counts of what
    they dropped (`take_dropped`) and tells the gate the ticks it plays (`window`)."""

    def __init__(self, budgets: dict[tuple[str, str], Allowance], members: Container[str],
                 window: tuple[int, int], clock: Callable[[], float] = time.monotonic):  # fmt: skip
        self.budgets = budgets
        self.members = members  # the agent processes that joined (the world's group index)
        self.window = window  # (first, last): the ticks an action may be for now; the world sets it each tick
        self.clock = clock
        self._lock = threading.Lock()
        self._all, self._looked, self._seen = itertools.count(), 0, 0  # every drop; looks at it; drops seen
        self._strangers = {space: self._bucket(space, STRANGERS) for space in PUTS}
        self._asking = {(s, kind): self._bucket(s, self.budgets.get((s, kind), ASKING)) for s in QUERIES
                        for kind in (NOW, OTHER)}  # fmt: skip
        self._alive = {kind: self._bucket(ALIVE, self.budgets.get((ALIVE, kind), STRANGERS)) for kind in (NOW, OTHER)}
        self._senders: dict[str, tuple[Bucket, Bucket, int]] = {}  # a member's key -> its (now, other) buckets, lag

    def _bucket(self, space: str, allowance: Allowance) -> Bucket:
        return Bucket(allowance, f"{space}: over budget", self.window[1], self.clock(), self._all)

    def _member(self, key: str, space: str) -> tuple[Bucket, Bucket, int]:
        """A member's buckets for its key (made once: two of zenoh's threads may ask at once)."""
        now, other = (self._bucket(space, self.budgets.get((space, kind), STRANGERS)) for kind in (NOW, OTHER))
        return self._senders.setdefault(key, (now, other, LAG.get(space, 0)))

    def take(self, space: str, sample) -> tuple[bytes, str] | None:
        """A put's (bytes, sender) when its sender's budget lets it in, else None (counted)."""
        key = str(sample.key_expr)
        sender = key[key.rfind("/") + 1 :]
        tick, clock = self.window[1], self.clock
        mine = self._senders.get(key)
        if mine is None:
            if sender in self.members:
                mine = self._member(key, space)
            else:  # a stranger's put is not even copied unless let in
                return (sample.payload.to_bytes(), sender) if self._admit(self._strangers[space]) else None
        now, other, lag = mine
        if other.closed(tick, clock) and now.closed(tick, clock):  # the usual flood, once the answer is in
            other.drop()
            return None
        raw = sample.payload.to_bytes()
        said, (first, last) = wire.peek_tick(raw), self.window
        bucket = now if said is not None and first - lag <= said <= last else other
        return (raw, sender) if self._admit(bucket) else None

    def let_alive(self, awaited: bool) -> bool:
        """May a liveliness change go to the world's thread?  One the world waits for (the token of an
        agent joining, the end of one in the run) draws on another bucket than the rest, so a client
        that declares tokens by the thousand on keys the world awaits nothing on spends only its own budget."""
        return self._admit(self._alive[NOW if awaited else OTHER])

    def let_in(self, space: str, query) -> bool:
        """Has a query budget left?  One that has not is dropped unanswered (counted)."""
        kind = OTHER
        if space == "join" and (payload := query.payload) is not None and len(payload) <= 1024:
            kind = NOW if JOIN_HEAD in payload.to_bytes()[:24] else OTHER
        if self._admit(self._asking[space, kind]):
            return True
        query.drop()
        return False

    def _admit(self, bucket: Bucket) -> bool:
        """Take a token from `bucket`: a closed one drops the message without the lock (counted)."""
        if bucket.closed(self.window[1], self.clock):
            bucket.drop()
            return False
        return self._spend(bucket)

    def _spend(self, bucket: Bucket) -> bool:
        with self._lock:
            return bucket.spend(self.window[1], self.clock)

    def take_dropped(self) -> dict[str, int]:
        """The messages dropped since the last call, by reason (each tick: one look when there are none)."""
        total = next(self._all) - self._looked
        self._looked += 1
        if total == self._seen:
            return {}
        self._seen = total
        dropped: dict[str, int] = {}
        senders = list(self._senders.values())  # in one step: zenoh's threads may add to it meanwhile
        buckets = [*self._strangers.values(), *self._asking.values(), *self._alive.values()]
        for bucket in [*buckets, *(b for s in senders for b in s[:2])]:
            if n := bucket.take_dropped():
                dropped[bucket.reason] = dropped.get(bucket.reason, 0) + n
        return dropped
