"""A secure router (swarm/core/acl.py's rules) with the world's subscriber behind it, and clients that
try what a forger would: puts on another agent process's keys and on the world's, sessions with no,
wrong or foreign credentials.  Counted at the world's subscriber: what got through."""

from __future__ import annotations

import json
import shutil
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import zenoh

from swarm.core import credentials
from swarm.core.bus import open_client, open_router
from swarm.core.mesh import free_endpoint
from swarm.core.wire import Keys

RUN = "bench"
STREAM = 20_000  # own puts timed per link kind (--quick: a tenth)


class _Heard:
    """The world's side: every sample on the run's keys, counted by key."""

    def __init__(self, session):
        self.by_key: dict[str, int] = {}
        self.lock = threading.Lock()
        self.sub = session.declare_subscriber(f"{Keys(RUN).prefix}/**", self._on)

    def _on(self, sample) -> None:
        with self.lock:
            key = str(sample.key_expr)
            self.by_key[key] = self.by_key.get(key, 0) + 1

    def count(self, key: str) -> int:
        with self.lock:
            return self.by_key.get(key, 0)

    def total(self) -> int:
        with self.lock:
            return sum(self.by_key.values())


def _refused(endpoint: str, identity: credentials.Identity | None, tries: int) -> int:
    """How many of `tries` sessions, opened at once (each waits out zenoh's 2 s connect timeout), the
    router refused."""

    def refused(_) -> bool:
        try:
            open_client(endpoint, timeout=0.5, identity=identity).close()
        except ConnectionError:
            return True
        return False

    with ThreadPoolExecutor(tries) as pool:
        return sum(pool.map(refused, range(tries)))


def _sessions(endpoint: str, logins: dict, tries: int) -> dict:
    return {what: {"tried": tries, "refused": _refused(endpoint, who, tries)} for what, who in logins.items()}


def _wrong_password(folder: Path, name: str, into: Path) -> credentials.Identity:
    """`name`'s folder with a password the router does not know."""
    copy = into / f"{name}-wrong"
    shutil.copytree(folder / name, copy, dirs_exist_ok=True)
    (copy / "identity.json").write_text(json.dumps({"user": name, "password": "guessed"}))
    return credentials.load(copy)


def _stream(endpoint: str, identity: credentials.Identity | None, router_identity, puts: int) -> float:
    """Puts per second from one agent process to the world's subscriber, counted as heard (by the
    router's own session: the world of `swarm up`)."""
    keys = Keys(RUN)
    router = open_router(endpoint, router_identity)
    heard = _Heard(router)
    agent = open_client(endpoint, identity=identity)
    try:
        key = keys.act(credentials.agent_name(1))
        pub = agent.declare_publisher(key, congestion_control=zenoh.CongestionControl.BLOCK)  # none dropped
        time.sleep(0.3)
        start = time.perf_counter()
        for _ in range(puts):
            pub.put(b"\x00" * 64)
        deadline = time.monotonic() + 30
        while heard.count(key) < puts and time.monotonic() < deadline:
            time.sleep(0.001)
        return round(heard.count(key) / (time.perf_counter() - start))
    finally:
        agent.close()
        router.close()


def run(quick: bool = False, forged: int = 1000) -> dict:
    forged = min(forged, 100) if quick else forged
    keys = Keys(RUN)
    with tempfile.TemporaryDirectory(prefix="swarm-bench-secure-") as tmp:
        folder = credentials.make(Path(tmp) / "run", 2)
        foreign = credentials.make(Path(tmp) / "other", 2)  # another run's CA and certificates
        me = credentials.identity_in(folder, credentials.agent_name(1))
        other = credentials.agent_name(2)
        result: dict = {"forged_per_key": forged}
        for scheme in ("tcp", "tls"):
            endpoint = free_endpoint(scheme)
            router = open_router(endpoint, credentials.identity_in(folder, credentials.ROUTER))
            world = open_client(endpoint, identity=credentials.identity_in(folder, credentials.WORLD))
            heard = _Heard(world)
            agent = open_client(endpoint, identity=me)
            monitor = open_client(endpoint, identity=credentials.identity_in(folder, credentials.MONITOR))
            try:
                time.sleep(0.3)
                targets = [keys.act(other), keys.mark(other), keys.plan(other), keys.record(other), keys.obs(other),
                           keys.state, keys.join, keys.info, keys.alive(0)]  # fmt: skip
                for key in targets:
                    for _ in range(forged):
                        agent.put(key, b"forged")
                for _ in range(forged):
                    monitor.put(keys.act(credentials.agent_name(1)), b"forged")
                own = keys.act(credentials.agent_name(1))
                for _ in range(forged):
                    agent.put(own, b"own")
                deadline = time.monotonic() + 10
                while heard.count(own) < forged and time.monotonic() < deadline:
                    time.sleep(0.01)
                time.sleep(0.3)
                tries = 5 if quick else 20
                logins = {"none": None, "wrong password": _wrong_password(folder, other, Path(tmp))}
                if scheme == "tls":
                    logins["another run's certificate"] = credentials.identity_in(foreign, other)
                result[scheme] = {
                    "forged_puts": forged * (len(targets) + 1),
                    "forged_heard": heard.total() - heard.count(own),
                    "own_puts": forged,
                    "own_heard": heard.count(own),
                    "sessions": _sessions(endpoint, logins, tries),
                }
            finally:
                for s in (monitor, agent, world, router):
                    s.close()
        router_id = credentials.identity_in(folder, credentials.ROUTER)
        puts = STREAM // 10 if quick else STREAM
        result["puts_per_s"] = {"plain tcp": _stream(free_endpoint("tcp"), None, None, puts),
                                "secure tcp": _stream(free_endpoint("tcp"), me, router_id, puts),
                                "secure tls": _stream(free_endpoint("tls"), me, router_id, puts)}  # fmt: skip
    return result


def format_secure_bench(result: dict) -> str:
    lines = ["Secure router (swarm/core/acl.py), the world's subscriber behind it; an agent process (agent1)",
             "puts on agent2's keys and on the world's, the monitor on agent1's action key; then sessions",
             "with no, wrong or foreign credentials.", "",
             f"{'link':>5}{'forged puts':>13}{'heard':>7}{'own puts':>10}{'heard':>7}  sessions refused"]  # fmt: skip
    for scheme in ("tcp", "tls"):
        r = result[scheme]
        refused = ", ".join(f"{what} {s['refused']}/{s['tried']}" for what, s in r["sessions"].items())
        lines.append(f"{scheme:>5}{r['forged_puts']:>13}{r['forged_heard']:>7}{r['own_puts']:>10}{r['own_heard']:>7}"
                     f"  {refused}")  # fmt: skip
    lines += ["", "puts/s, one agent process to the world's router (64 B each, all heard): "
              + ", ".join(f"{k} {v}" for k, v in result["puts_per_s"].items())]  # fmt: skip
    return "\n".join(lines)
