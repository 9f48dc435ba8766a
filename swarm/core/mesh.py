"""Routers meshed through one name: how the zenoh routers of a deployment find each other.

Overlay networks (Docker Swarm) and pod networks (Kubernetes) carry no multicast, so zenoh's
scouting finds nothing there.  A DNS name that resolves to every router's address does: a Docker
Swarm service with `endpoint_mode: dnsrr`, a Kubernetes headless service.  Each router connects
to every address but its own; one link per pair is enough, so a router that starts later links to
those before it, and zenoh retries the links to routers that are gone or not up yet.  Two routers
that start together could each resolve the name before the other is listed; so a router first
waits until the name lists itself, then `settle` seconds more (longer than the name takes to
reach the other nodes), and only then reads the others: the later of the two sees the earlier.

Under load a name's records can reach the other nodes later still, and then neither of two routers
ever links to the other, and their processes never hear each other.  So a router keeps reading the
name (`Mesh`): when it lists more routers than this one is linked with, for longer than zenoh's
own retries take, each router found after this one opened gets a bridge, a second router in this
process with no listener, linked to both (zenoh reads a router's links only when it opens).
"""

from __future__ import annotations

import re
import socket
import time
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import zenoh


def split(endpoint: str) -> tuple[str, str, int]:
    """("tcp", "router", 7447) from "tcp/router:7447" (zenoh's ?metadata and #config left out)."""
    proto, sep, rest = re.split(r"[?#]", endpoint, maxsplit=1)[0].partition("/")
    host, colon, port = rest.rpartition(":")
    if not (sep and colon and proto and host and port.isdigit()):
        raise ValueError(f"{endpoint!r}: expected PROTOCOL/NAME:PORT, e.g. tcp/router:7447")
    return proto, host.strip("[]"), int(port)


def resolve(host: str, port: int) -> list[str]:
    """Every address `host` resolves to now, sorted; none if it does not resolve (yet)."""
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except socket.gaierror:
        return []
    return sorted({info[4][0] for info in infos})


def is_own(address: str) -> bool:
    """Whether `address` is one of this host's: only those can be bound to."""
    family = socket.AF_INET6 if ":" in address else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as probe:
        try:
            probe.bind((address, 0))
        except OSError:
            return False
        return True


def others(endpoint: str, wait: float = 20.0, settle: float = 3.0,
           sleep: Callable[[float], None] = time.sleep) -> list[str]:  # fmt: skip
    """The endpoints of every other router the name of `endpoint` lists.  Waits up to `wait` s
    for the name to list this host (it may never: a name that lists the others only), then `settle` s."""
    _, host, port = split(endpoint)
    deadline = time.monotonic() + wait
    while not any(is_own(a) for a in resolve(host, port)) and time.monotonic() < deadline:
        sleep(0.5)
    sleep(settle)
    return listed_others(endpoint)


def listed_others(endpoint: str) -> list[str]:
    """The endpoints of every other router the name of `endpoint` lists now."""
    proto, host, port = split(endpoint)
    return [_endpoint(proto, a, port) for a in resolve(host, port) if not is_own(a)]


def _endpoint(proto: str, host: str, port: int) -> str:
    return f"{proto}/[{host}]:{port}" if ":" in host else f"{proto}/{host}:{port}"


def local(listen: str) -> str:
    """Where a process on this host reaches the router that listens on `listen`."""
    proto, host, port = split(listen)
    near = {"0.0.0.0": "127.0.0.1", "::": "::1"}.get(host, host)
    return _endpoint(proto, near, port)


def _linked(router: zenoh.Session) -> set[str]:
    """The zids of the routers linked to `router`."""
    return {str(zid) for zid in router.info.routers_zid()}


class Mesh:
    """Keeps `router` linked to every router `listed()` gives, also those found after it opened
    (module docstring).  `configured`: the endpoints it was opened with, which zenoh retries itself;
    `open_bridge(far)`: a router session linked to this one and to `far`."""

    def __init__(self, router: zenoh.Session, listed: Callable[[], Iterable[str]], configured: Iterable[str],
                 open_bridge: Callable[[str], zenoh.Session], grace: float = 10.0,
                 clock: Callable[[], float] = time.monotonic) -> None:  # fmt: skip
        self.router, self.listed, self.open_bridge = router, listed, open_bridge
        self.grace, self.clock = grace, clock
        self.tried = set(configured)  # configured, bridged, or found linked through the other's own link
        self.bridges: dict[str, zenoh.Session] = {}
        self.short_since: float | None = None

    def linked(self) -> set[str]:
        """The zids of the other routers this one is linked with, directly or through a bridge."""
        own = {str(self.router.zid())}
        bridges = {str(b.zid()) for b in self.bridges.values()}
        behind = set().union(*(_linked(b) for b in self.bridges.values()))
        return (_linked(self.router) | behind) - bridges - own

    def check(self) -> list[str]:
        """One look at the names: the endpoints bridged by it."""
        listed = set(self.listed())
        for gone in set(self.bridges) - listed:  # its router left the name: nothing to link with
            self.bridges.pop(gone).close()
        if len(self.linked()) >= len(listed):
            self.short_since = None
            return []
        now = self.clock()
        if self.short_since is None:
            self.short_since = now
        if now - self.short_since < self.grace:  # a link still being opened, by either side
            return []
        self.short_since = now  # the next round after as long again
        bridged = []
        for far in sorted(listed - self.tried):
            already = self.linked()
            try:
                bridge = self.open_bridge(far)
            except ConnectionError:
                continue  # tried again next round
            beyond = _linked(bridge) - {str(self.router.zid())}
            if beyond:
                self.tried.add(far)
            if not beyond or beyond <= already:
                bridge.close()  # not up (yet: tried again next round), or its router had linked to this one
                continue
            self.bridges[far] = bridge
            bridged.append(far)
        return bridged

    def close(self) -> None:
        for bridge in self.bridges.values():
            bridge.close()
        self.bridges.clear()
