"""Zenoh sessions: the embedded router and clients, loopback and no multicast by default.

Facts this relies on (zenoh-python 1.x): sessions must be closed explicitly;
callbacks run on zenoh's threads, so they only enqueue; sessions do not
survive fork (agents are started with `spawn` or as separate commands).
"""

from __future__ import annotations

import json
import re
import time

import zenoh

DEFAULT_ENDPOINT = "tcp/127.0.0.1:7447"


def config(mode: str, listen: list[str] | None = None, connect: list[str] | None = None) -> zenoh.Config:
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
    return c


def _said(exc: Exception) -> str:
    """zenoh's error without the Rust source locations it appends."""
    return re.sub(r" at /\S+\.rs:\d+\.?", "", str(exc))


def open_router(listen: str = DEFAULT_ENDPOINT) -> zenoh.Session:
    """A session in router mode: the embedded router every other process joins."""
    try:
        return zenoh.open(config("router", listen=[listen]))
    except zenoh.ZError as exc:
        raise ConnectionError(
            f"cannot listen on {listen} ({_said(exc)}); is another world running? pick another --listen"
        ) from None


def open_client(connect: str = DEFAULT_ENDPOINT, timeout: float = 30.0) -> zenoh.Session:
    """A client session, retried until the router answers or `timeout` passes."""
    deadline = time.monotonic() + timeout
    while True:
        try:
            return zenoh.open(config("client", connect=[connect]))
        except zenoh.ZError as exc:
            if time.monotonic() > deadline:
                raise ConnectionError(
                    f"no zenoh router at {connect} after {timeout:.0f} s ({_said(exc)}); start `swarm world` first"
                ) from None
            time.sleep(0.2)
