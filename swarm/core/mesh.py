"""Routers meshed through one name: how the zenoh routers of a deployment find each other.

Overlay networks (Docker Swarm) and pod networks (Kubernetes) carry no multicast, so zenoh's
scouting finds nothing there.  A DNS name that resolves to every router's address does: a Docker
Swarm service with `endpoint_mode: dnsrr`, a Kubernetes headless service.  Each router connects
to every address but its own; one link per pair is enough, so a router that starts later links to
those before it, and zenoh retries the links to routers that are gone or not up yet.  Two routers
that start together could each resolve the name before the other is listed; so a router first
waits until the name lists itself, then `settle` seconds more (longer than the name takes to
reach the other nodes), and only then reads the others: the later of the two sees the earlier.
"""

from __future__ import annotations

import re
import socket
import time
from collections.abc import Callable


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
    proto, host, port = split(endpoint)
    deadline = time.monotonic() + wait
    while not any(is_own(a) for a in resolve(host, port)) and time.monotonic() < deadline:
        sleep(0.5)
    sleep(settle)
    return [f"{proto}/[{a}]:{port}" if ":" in a else f"{proto}/{a}:{port}"
            for a in resolve(host, port) if not is_own(a)]  # fmt: skip
