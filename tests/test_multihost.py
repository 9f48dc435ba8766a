"""Several hosts without Docker: router, world and agents each in its own network
namespace (`ip netns`), joined by veth pairs on a bridge, with their own
addresses, talking TCP.  One agent's link is cut mid-run: the world declares it
lost and the run goes on; the link is restored: the agent joins again.

The addresses (10.201.0.0/24) exist only inside the namespaces this test makes;
no traffic leaves them.  Needs root and `ip` (iproute2).
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import subprocess
import sys
import time
import uuid

import pytest

pytestmark = pytest.mark.timeout(600)

NODES = ("router", "world", "a1", "a2", "a3")
SUBNET = "10.201.0"
LINK_DOWN_SECONDS = 15
RATE_HZ = 50  # setup1 needs > 13,000 ticks: over 4 minutes at this rate


def _ip(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    return subprocess.run(["ip", *args], capture_output=True, text=True, check=check, timeout=30)


def _netns_available() -> str | None:
    if os.geteuid() != 0 or shutil.which("ip") is None:
        return "needs root and iproute2's ip"
    probe = f"swprobe{uuid.uuid4().hex[:4]}"
    if _ip("netns", "add", probe, check=False).returncode != 0:
        return "network namespaces cannot be made here"
    _ip("netns", "del", probe, check=False)
    return None


reason = _netns_available()
if reason is not None:
    pytest.skip(f"multi-host test: {reason}", allow_module_level=True)


class Hosts:
    """A bridge in a hub namespace and one namespace per host, each with eth0 on the bridge."""

    def __init__(self):
        self.prefix = f"sw{uuid.uuid4().hex[:4]}"
        self.hub = f"{self.prefix}hub"
        self.addr = {node: f"{SUBNET}.{i}" for i, node in enumerate(NODES, start=1)}
        self.procs: list[subprocess.Popen] = []
        _ip("netns", "add", self.hub)
        _ip("-n", self.hub, "link", "add", "br0", "type", "bridge")
        _ip("-n", self.hub, "link", "set", "br0", "up")
        for node in NODES:
            ns, host_end, node_end = self.ns(node), self.link(node), f"{self.prefix}n{node[:2]}"
            _ip("netns", "add", ns)
            _ip("link", "add", host_end, "type", "veth", "peer", "name", node_end)
            _ip("link", "set", host_end, "netns", self.hub)
            _ip("link", "set", node_end, "netns", ns)
            _ip("-n", ns, "link", "set", node_end, "name", "eth0")
            _ip("-n", ns, "addr", "add", f"{self.addr[node]}/24", "dev", "eth0")
            _ip("-n", ns, "link", "set", "eth0", "up")
            _ip("-n", ns, "link", "set", "lo", "up")
            _ip("-n", self.hub, "link", "set", host_end, "master", "br0", "up")

    def ns(self, node: str) -> str:
        return f"{self.prefix}{node[:2]}"

    def link(self, node: str) -> str:
        """The node's cable, as the hub sees it: set it down to cut the host off."""
        return f"{self.prefix}h{node[:2]}"

    def start(self, node: str, *args: str, log) -> subprocess.Popen:
        cmd = ["ip", "netns", "exec", self.ns(node), sys.executable, "-m", "swarm", *args]
        proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
        self.procs.append(proc)
        return proc

    def status(self, run_id: str) -> dict | None:
        out = subprocess.run(
            ["ip", "netns", "exec", self.ns("router"), sys.executable, "-m", "swarm", "status", "--json",
             "--connect", f"tcp/{self.addr['router']}:7447", "--run-id", run_id],
            capture_output=True, text=True, timeout=60)  # fmt: skip
        return json.loads(out.stdout) if out.returncode == 0 else None

    def close(self) -> None:
        for p in self.procs:
            if p.poll() is None:
                p.terminate()
        for p in self.procs:
            try:
                p.wait(timeout=15)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait(timeout=10)
        for node in NODES:
            _ip("netns", "del", self.ns(node), check=False)
        _ip("netns", "del", self.hub, check=False)


@pytest.fixture
def hosts():
    h = Hosts()
    try:
        yield h
    finally:
        h.close()


def _wait(hosts: Hosts, run_id: str, what: str, ok, timeout: float) -> dict:
    deadline = time.monotonic() + timeout
    info = None
    while time.monotonic() < deadline:
        info = hosts.status(run_id)
        if info is not None and ok(info):
            return info
        time.sleep(0.5)
    raise AssertionError(f"{what}: not within {timeout:.0f} s; the world said {info}")


def test_an_agent_cut_off_is_lost_and_rejoins_when_its_link_returns(hosts, tmp_path):
    run_id = f"hosts{uuid.uuid4().hex[:6]}"
    router = f"tcp/{hosts.addr['router']}:7447"
    with open(tmp_path / "processes.log", "w") as log:
        hosts.start("router", "router", "--listen", router, log=log)
        # Real time at a fixed rate: the run lasts minutes of wall-clock time however fast the machine
        # is (lock-step setup1 ends in ~20 s on a fast one, before the cut link comes back).
        world = hosts.start("world", "world", "setup1", "--agents", "3", "--seed", "1", "--connect", router,
                            "--run-id", run_id, "--mode", "realtime", "--rate", str(RATE_HZ),
                            "--max-misses", str(RATE_HZ // 2), "--state-dir", str(tmp_path), log=log)  # fmt: skip
        for agent in ("a1", "a2", "a3"):
            hosts.start(agent, "agent", "--connect", router, "--run-id", run_id, log=log)
        try:
            _wait(hosts, run_id, "3 agents ticking", lambda i: i["agents_alive"] == 3 and i["tick"] > 50, 300)

            _ip("-n", hosts.hub, "link", "set", hosts.link("a1"), "down")  # cut a1 off
            cut = time.monotonic()
            lost = _wait(hosts, run_id, "the world declares the cut agent lost",
                         lambda i: i["agents_lost"] >= 1 and i["agents_alive"] == 2, 60)  # fmt: skip
            goes_on = _wait(hosts, run_id, "the run goes on with 2 agents",
                            lambda i: i["tick"] > lost["tick"] + 100 and i["agents_alive"] == 2, 60)  # fmt: skip
            assert not goes_on["ended"]
            # Longer than zenoh's lease (10 s): the agent's session to the router is gone and must reconnect.
            time.sleep(max(0.0, cut + LINK_DOWN_SECONDS - time.monotonic()))

            _ip("-n", hosts.hub, "link", "set", hosts.link("a1"), "up")  # restore the link
            back = _wait(hosts, run_id, "the agent joins again",
                         lambda i: i["joins"] >= 4 and i["agents_alive"] == 3, 90)  # fmt: skip
            again = _wait(hosts, run_id, "3 agents tick on", lambda i: i["tick"] > back["tick"] + 100, 60)
            assert again["agents_alive"] == 3 and not again["ended"]
        except AssertionError:
            log.flush()
            print((tmp_path / "processes.log").read_text()[-4000:])
            raise
        world.terminate()
        with contextlib.suppress(subprocess.TimeoutExpired):
            assert world.wait(timeout=30) in (130, 0), "the world did not stop cleanly on SIGTERM"
