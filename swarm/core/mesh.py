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
name (`Mesh`): a router it lists whose host has no link with this one, for longer than zenoh's own
retries take, gets a bridge, a second router in this process with no listener, linked to both
(zenoh reads a router's links only when it opens).  A look counts only when the name lists this
router too: a lookup that fails under load, or a name this router has left, says nothing about
the others.
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
    try:
        with socket.socket(family, socket.SOCK_STREAM) as probe:
            probe.bind((address, 0))
    except OSError:  # not ours, or no such family here (IPv6 off)
        return False
    return True


def others(endpoint: str, wait: float = 20.0, settle: float = 3.0,
           sleep: Callable[[float], None] = time.sleep) -> list[str]:  # fmt: skip
    """The endpoints of every other router the name of `endpoint` lists.  Waits up to `wait` s
    for the name to list this host (it may never: a name that lists the others only), then `settle` s."""
    deadline = time.monotonic() + wait
    while not _look(endpoint)[0] and time.monotonic() < deadline:
        sleep(0.5)
    sleep(settle)
    return _look(endpoint)[1]


def listed_others(endpoint: str) -> list[str] | None:
    """The endpoints of every other router the name of `endpoint` lists now; None unless it lists this
    host too (the lookup failed, or this router has left the name: nothing to tell of the others)."""
    lists_this_host, found = _look(endpoint)
    return found if lists_this_host else None


def _look(endpoint: str) -> tuple[bool, list[str]]:
    """One lookup of the name of `endpoint`: whether it lists this host, and the endpoints of the others."""
    proto, host, port = split(endpoint)
    addresses = resolve(host, port)
    own = [is_own(a) for a in addresses]
    return any(own), [_endpoint(proto, a, port) for a, mine in zip(addresses, own, strict=True) if not mine]


def listed(names: Iterable[str]) -> list[str] | None:
    """`listed_others` of every name that lists this router; None when none does."""
    found = [listed_others(name) for name in names]
    return None if all(f is None for f in found) else [e for f in found if f is not None for e in f]


def free_port() -> int:
    """A TCP port of 127.0.0.1 that is free now (the system's pick): for a router, a Ray head or a test."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def free_endpoint(scheme: str = "tcp") -> str:
    """A zenoh endpoint on 127.0.0.1 at a `free_port`: `tcp/127.0.0.1:PORT` (or `tls/...`)."""
    return f"{scheme}/127.0.0.1:{free_port()}"


def _endpoint(proto: str, host: str, port: int) -> str:
    return f"{proto}/[{host}]:{port}" if ":" in host else f"{proto}/{host}:{port}"


def local(listen: str) -> str:
    """Where a process on this host reaches the router that listens on `listen`."""
    proto, host, port = split(listen)
    near = {"0.0.0.0": "127.0.0.1", "::": "::1"}.get(host, host)
    return _endpoint(proto, near, port)


def host_of(locator: str) -> str:
    """The host of a zenoh endpoint or locator: "10.0.0.3" from "tcp/10.0.0.3:7447"."""
    return split(locator)[1]


class Mesh:
    """Keeps `router` linked to every router `listed()` gives, also those found after it opened
    (module docstring): routers are told apart by host, as a name lists them.  `listed()`: None for a
    look that tells nothing; `configured`: the endpoints it opened with, which zenoh links (and links
    again) itself; `open_bridge(far)`: a router session linked to this one and to `far`."""

    def __init__(self, router: zenoh.Session, listed: Callable[[], Iterable[str] | None], configured: Iterable[str],
                 open_bridge: Callable[[str], zenoh.Session], grace: float = 10.0,
                 clock: Callable[[], float] = time.monotonic) -> None:  # fmt: skip
        self.router, self.listed, self.configured, self.open_bridge = router, listed, set(configured), open_bridge
        self.grace, self.clock = grace, clock
        self.bridges: dict[str, zenoh.Session] = {}  # by the endpoint of the router each links to
        self.missing_since: dict[str, float] = {}  # listed routers with no link, since when

    def linked_hosts(self) -> set[str]:
        """The hosts of the routers this one has a link with, its own or a bridge's."""
        bridges = {str(b.zid()) for b in self.bridges.values()}
        routers = {str(zid) for zid in self.router.info.routers_zid()} - bridges
        own = str(self.router.zid())
        hosts = {host_of(link.dst) for link in self.router.info.links() if str(link.zid) in routers}
        for bridge in self.bridges.values():
            hosts |= {host_of(link.dst) for link in bridge.info.links() if str(link.zid) != own}
        return hosts

    def check(self) -> list[str]:
        """One look at the names: the endpoints bridged by it."""
        found = self.listed()
        if found is None:
            return []
        listed, now, linked = set(found), self.clock(), self.linked_hosts()
        for far in [f for f in self.bridges if f not in listed and host_of(f) not in linked]:
            self.bridges.pop(far).close()  # its router left the name and cannot be reached: gone
        missing = sorted(f for f in listed - self.configured - set(self.bridges) if host_of(f) not in linked)
        self.missing_since = {far: self.missing_since.get(far, now) for far in missing}
        bridged = []
        for far in missing:
            if now - self.missing_since[far] < self.grace:  # a link still being opened, by either side
                continue
            try:
                self.bridges[far] = self.open_bridge(far)  # kept: zenoh retries its far link until it holds
            except ConnectionError:
                continue  # tried again next round
            del self.missing_since[far]
            bridged.append(far)
        return bridged

    def close(self) -> None:
        for bridge in self.bridges.values():
            bridge.close()
        self.bridges.clear()
