"""Routers meshed through a name (swarm/core/mesh.py, `swarm router --mesh`): which endpoints a
router links to, and that two routers so linked carry a client's messages to another's.  The
mesh on a real overlay network, with names that list every router, is tests/test_compose.py's
stack test."""

from __future__ import annotations

import subprocess
import sys
import time

import pytest

from swarm.core.bus import open_bridge, open_client, open_router
from swarm.core.mesh import Mesh, is_own, local, others, split
from tests.distributed import free_endpoint


def test_a_router_links_to_every_address_but_its_own():
    assert is_own("127.0.0.1") and not is_own("192.0.2.7")  # TEST-NET-1: never a host's own
    assert others("tcp/localhost:7447", wait=1, settle=0) == []  # lists this host only
    assert others("tcp/192.0.2.7:7447", wait=0.2, settle=0) == ["tcp/192.0.2.7:7447"]
    assert others("tcp/no-such-router.invalid:7447", wait=0.2, settle=0) == []  # not (yet) in the DNS
    # a bridge reaches its own router where that listens
    assert local("tcp/0.0.0.0:7447") == "tcp/127.0.0.1:7447" and local("tls/[::]:7447") == "tls/[::1]:7447"
    assert local("tcp/10.0.0.3:7447") == "tcp/10.0.0.3:7447"


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
    try:
        assert _carries(later, earlier)
    finally:
        second.close()
        first.close()


def _carries(near: str, far: str) -> bool:
    """Whether a put by a client of the router at `near` reaches a subscriber on the router at `far`."""
    a, b = open_client(near), open_client(far)
    got: list[str] = []
    try:
        sub = b.declare_subscriber("mesh/**", lambda sample: got.append(sample.payload.to_string()))
        deadline = time.monotonic() + 10
        while not got and time.monotonic() < deadline:
            a.put("mesh/hello", "across")
            time.sleep(0.2)
        sub.undeclare()
        return got[:1] == ["across"]
    finally:
        a.close()
        b.close()


def _on(host: str) -> str:
    """A free endpoint on loopback address `host`: routers on hosts of their own, as a name lists them."""
    return free_endpoint().replace("127.0.0.1", host)


def _until(condition, timeout: float = 15.0) -> bool:
    deadline = time.monotonic() + timeout
    while not condition() and time.monotonic() < deadline:
        time.sleep(0.1)
    return condition()


def test_two_routers_that_missed_each_other_are_bridged_once():
    """Each read the name before it listed the other (no links): the one that looks again bridges them."""
    near, far = _on("127.0.0.2"), _on("127.0.0.3")
    first, second = open_router(near), open_router(far)
    opened: list[str] = []

    def bridge(to: str):
        opened.append(to)
        return open_bridge(near, to)

    keeper = Mesh(first, lambda: [far], [], bridge, grace=0)
    try:
        assert keeper.check() == [far] and _until(lambda: keeper.linked_hosts() == {"127.0.0.3"})
        assert _carries(near, far) and _carries(far, near)
        assert keeper.check() == [] and opened == [far]  # linked: never bridged again
    finally:
        keeper.close()
        second.close()
        first.close()


def test_a_look_that_tells_nothing_keeps_the_bridges_and_a_router_back_is_bridged_again():
    """A failed lookup (None) or one without a router still linked closes nothing; a router gone from the
    name and from the links loses its bridge, and gets a new one when it is back."""
    near, far = _on("127.0.0.2"), _on("127.0.0.3")
    first, second = open_router(near), open_router(far)
    names: list[list[str] | None] = [[far]]
    keeper = Mesh(first, lambda: names[-1], [], lambda to: open_bridge(near, to), grace=0)
    back = None
    try:
        assert keeper.check() == [far] and _until(lambda: "127.0.0.3" in keeper.linked_hosts())
        for look in (None, []):  # the lookup failed; the name left it out, its router still linked
            names.append(look)
            assert keeper.check() == [] and set(keeper.bridges) == {far}
        second.close()
        assert _until(lambda: "127.0.0.3" not in keeper.linked_hosts())
        assert keeper.check() == [] and keeper.bridges == {}  # gone from the name and the links
        back = open_router(far)
        names.append([far])
        assert keeper.check() == [far] and _until(lambda: "127.0.0.3" in keeper.linked_hosts())
        assert _carries(far, near)
    finally:
        keeper.close()
        for session in (back, first):
            if session is not None:
                session.close()


def test_a_router_waits_out_the_grace_and_bridges_none_it_is_linked_with():
    """A later router that linked itself, or one zenoh links as configured, is no reason for a bridge; a
    listed one not up yet gets its bridge after the grace, which links once it is up."""
    near, far, absent, configured = _on("127.0.0.2"), _on("127.0.0.3"), _on("127.0.0.4"), _on("127.0.0.5")
    first = open_router(near)
    second = open_router(far, connect=[f"{near}#bind=127.0.0.3:0"])  # the later one, which saw the earlier
    now = [0.0]
    keeper = Mesh(first, lambda: [far, absent, configured], [configured], lambda to: open_bridge(near, to),
                  grace=10, clock=lambda: now[0])  # fmt: skip
    late = None
    try:
        assert _until(lambda: keeper.linked_hosts() == {"127.0.0.3"})
        assert keeper.check() == []  # absent: missing from now on, within the grace
        now[0] = 9.0
        assert keeper.check() == []
        now[0] = 11.0
        assert keeper.check() == [absent] and set(keeper.bridges) == {absent}  # far linked; configured: zenoh's
        late = open_router(absent)
        assert _until(lambda: keeper.linked_hosts() == {"127.0.0.3", "127.0.0.4"}, timeout=20)
        assert _carries(absent, far)  # through the first router and its bridge
    finally:
        keeper.close()
        for session in (late, second, first):
            if session is not None:
                session.close()
