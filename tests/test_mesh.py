"""Routers meshed through a name (swarm/core/mesh.py, `swarm router --mesh`): which endpoints a
router links to, and that two routers so linked carry a client's messages to another's.  The
mesh on a real overlay network, with names that list every router, is tests/test_compose.py's
stack test."""

from __future__ import annotations

import subprocess
import sys
import time

import pytest

from swarm.core.bus import open_client, open_router
from swarm.core.mesh import is_own, others, split
from tests.distributed import free_endpoint


def test_a_router_links_to_every_address_but_its_own():
    assert is_own("127.0.0.1") and not is_own("192.0.2.7")  # TEST-NET-1: never a host's own
    assert others("tcp/localhost:7447", wait=1, settle=0) == []  # lists this host only
    assert others("tcp/192.0.2.7:7447", wait=0.2, settle=0) == ["tcp/192.0.2.7:7447"]
    assert others("tcp/no-such-router.invalid:7447", wait=0.2, settle=0) == []  # not (yet) in the DNS


def test_a_bad_mesh_endpoint_is_one_line():
    assert split("tcp/router:7447?iface=eth0#rx_buffer_size=65536") == ("tcp", "router", 7447)  # zenoh's extras
    with pytest.raises(ValueError, match="expected PROTOCOL/NAME:PORT"):
        split("router:7447")
    out = subprocess.run([sys.executable, "-m", "swarm", "router", "--mesh", "router"], capture_output=True,
                         text=True, timeout=60)  # fmt: skip
    assert out.returncode == 2 and out.stderr.strip().splitlines()[-1].endswith(
        "argument --mesh: 'router': expected PROTOCOL/NAME:PORT, e.g. tcp/router:7447"), out.stderr  # fmt: skip


def test_two_linked_routers_carry_messages_between_their_clients():
    later, earlier = free_endpoint(), free_endpoint()
    first = open_router(earlier)
    second = open_router(later, connect=[earlier])  # what --mesh gives the router that starts later
    a, b = open_client(later), open_client(earlier)
    got: list[str] = []
    try:
        sub = b.declare_subscriber("mesh/**", lambda sample: got.append(sample.payload.to_string()))
        deadline = time.monotonic() + 10
        while not got and time.monotonic() < deadline:
            a.put("mesh/hello", "across")
            time.sleep(0.2)
        sub.undeclare()
        assert got and got[0] == "across"
    finally:
        for session in (a, b, second, first):
            session.close()
