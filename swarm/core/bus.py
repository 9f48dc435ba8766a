"""Zenoh sessions: the embedded router and clients, loopback and no multicast by default.

Facts this relies on (zenoh-python 1.x): sessions must be closed explicitly;
callbacks run on zenoh's threads, so they only enqueue; sessions do not
survive fork (agents are started with `spawn` or as separate commands).

With an `Identity` (swarm/core/credentials.py) a session logs in with its
user and password, and on `tls/` endpoints shows its certificate and checks
the router's against the run's CA; a router with one checks every login
against its dictionary and enforces swarm/core/acl.py's rules.  Without one,
nothing is added: plain runs are configured exactly as before.
"""

from __future__ import annotations

import json
import re
import time

import zenoh

from swarm.core.acl import access_control
from swarm.core.credentials import Identity

DEFAULT_ENDPOINT = "tcp/127.0.0.1:7447"

# zenoh drops a put (by default) when the link's queue has no room within 1 ms, or 50 ms for a message
# in fragments, and the queue holds two 64 KB batches: a machine busy elsewhere loses an animat's map or
# memory that way.  A lock-step tick that loses an observation or an answer waits out its deadline and
# moves robots differently, so the run's own messages wait for room instead; a peer that stops reading
# for `congestion_control/block/wait_before_close` (5 s) is cut off, and the world counts it lost.
LOSSLESS = zenoh.CongestionControl.BLOCK


def config(mode: str, listen: list[str] | None = None, connect: list[str] | None = None,
           identity: Identity | None = None) -> zenoh.Config:  # fmt: skip
    c = zenoh.Config()
    c.insert_json5("mode", json.dumps(mode))
    c.insert_json5("scouting/multicast/enabled", "false")
    # No shared-memory pool for big messages: it maps 16 MB into every process (counted in its
    # resident memory) for ~10% more ticks/s on one host only; hosts and containers use TCP anyway.
    c.insert_json5("transport/shared_memory/transport_optimization/enabled", "false")
    if listen:
        c.insert_json5("listen/endpoints", json.dumps(listen))
    if connect:
        c.insert_json5("connect/endpoints", json.dumps(connect))
        # Fail over to retries here rather than hang: the router may still be starting.
        c.insert_json5("connect/timeout_ms", "2000")
    if identity is not None:
        _secure(c, mode, [*(listen or []), *(connect or [])], identity)
    return c


def _secure(c: zenoh.Config, mode: str, endpoints: list[str], me: Identity) -> None:
    """Login, TLS certificates and, for a router, the dictionary and the access rules."""
    tls = any(e.startswith("tls/") for e in endpoints)
    login = {"user": me.name, "password": me.password}
    if mode == "router":
        login["dictionary_file"] = str(me.users_file)
        c.insert_json5("access_control", json.dumps(access_control(me.users(), tls)))
    c.insert_json5("transport/auth/usrpwd", json.dumps(login))
    if tls:
        # A router shows its certificate on the links it opens to its mesh peers too.  It reaches them
        # by addresses its name resolves to, which no certificate can list in advance: the CA and the
        # peer's name (`router`, checked by the access rules) stand for the host name there.
        tls_config: dict = {"root_ca_certificate": str(me.ca), "enable_mtls": True}
        for side in ("listen", "connect") if mode == "router" else ("connect",):
            tls_config.update({f"{side}_certificate": str(me.cert), f"{side}_private_key": str(me.key)})
        if mode == "router":
            tls_config["verify_name_on_connect"] = False
        c.insert_json5("transport/link/tls", json.dumps(tls_config))


def _said(exc: Exception) -> str:
    """zenoh's error without the Rust source locations it appends."""
    return re.sub(r" at /\S+\.rs:\d+\.?", "", str(exc))


def open_router(listen: str = DEFAULT_ENDPOINT, identity: Identity | None = None,
                connect: list[str] | None = None) -> zenoh.Session:  # fmt: skip
    """A session in router mode: the embedded router every other process joins; linked to the
    routers at `connect` (zenoh keeps retrying those that do not answer)."""
    try:
        return zenoh.open(config("router", listen=[listen], connect=connect, identity=identity))
    except zenoh.ZError as exc:
        raise ConnectionError(
            f"cannot listen on {listen} ({_said(exc)}); is another world running? pick another --listen"
        ) from None


def open_bridge(near: str, far: str, identity: Identity | None = None) -> zenoh.Session:
    """A router with no listener, linked to the routers at `near` and `far`: routers forward through
    each other, so the two are linked through it (zenoh cannot add a link to an open session)."""
    c = config("router", connect=[near, far], identity=identity)
    c.insert_json5("listen/endpoints", "[]")  # not zenoh's default for a router, the port `near` holds
    try:
        return zenoh.open(c)
    except zenoh.ZError as exc:
        raise ConnectionError(f"cannot open a router linked to {near} and {far} ({_said(exc)})") from None


def open_client(connect: str = DEFAULT_ENDPOINT, timeout: float = 30.0, identity: Identity | None = None
                ) -> zenoh.Session:  # fmt: skip
    """A client session, retried until the router answers or `timeout` passes."""
    deadline = time.monotonic() + timeout
    while True:
        try:
            return zenoh.open(config("client", connect=[connect], identity=identity))
        except zenoh.ZError as exc:
            if time.monotonic() > deadline:
                hint = (f"or it refused the credentials of {identity.name!r}" if identity is not None
                        else "start `swarm world` first")  # fmt: skip
                raise ConnectionError(f"no zenoh router at {connect} after {timeout:.0f} s ({_said(exc)}); {hint}"
                                      ) from None  # fmt: skip
            time.sleep(0.2)
