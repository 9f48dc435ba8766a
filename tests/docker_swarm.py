"""A two-node Docker Swarm on one machine: the test's engine as manager, and a second engine, in
its own network namespace joined to this one by a veth pair, as worker.

The second engine gets its own data and run folders and socket; it runs in the namespace
(`nsenter --net`, which keeps the cgroup mounts that `ip netns exec` would hide), so its
bridges, iptables rules and VXLAN port are its own, and the overlay network between the two
nodes crosses the veth pair like a cable between hosts.  The image is copied over with
`docker save | docker load`, since no registry is reachable.  Everything is undone on exit:
the stacks' containers, both nodes' swarm membership, the engine, its folders and the namespace.
"""

from __future__ import annotations

import contextlib
import shutil
import subprocess
import time
import uuid
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

SUBNET = "10.203.0"  # the veth pair's addresses: the manager .1 (this namespace), the worker .2
WORLD_LABEL = "swarm.world=true"  # stack.yaml puts the world on the node with this label


def why_no_second_node() -> str | None:
    """None if a second engine can be started in a network namespace here, else why not."""
    for tool in ("ip", "nsenter", "dockerd"):
        if shutil.which(tool) is None:
            return f"no {tool}"
    return None


def docker(*args: str, host: str | None = None, check: bool = True, timeout: float = 120,
           **kwargs) -> subprocess.CompletedProcess:  # fmt: skip
    where = ["-H", host] if host else []
    return subprocess.run(["docker", *where, *args], capture_output=True, text=True, check=check, timeout=timeout,
                          **kwargs)  # fmt: skip


def _run(*cmd: str, check: bool = True) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, capture_output=True, text=True, check=check, timeout=60)


@dataclass
class Nodes:
    manager: str  # node ids
    worker: str
    worker_host: str  # the worker engine's socket, for docker -H

    def stack_containers(self, stack: str) -> list[str]:
        label = f"label=com.docker.stack.namespace={stack}"
        return [c for host in (None, self.worker_host)
                for c in docker("ps", "-aq", "--filter", label, host=host, check=False).stdout.split()]  # fmt: skip


@contextlib.contextmanager
def _second_engine(tag: str) -> Iterator[str]:
    """A dockerd in the namespace `tag`, reached at 10.203.0.2; yields its socket."""
    ns, link, folder = tag, f"{tag}v", Path(f"/run/{tag}")
    data = Path(f"/var/lib/{tag}")
    sock = f"unix://{folder}/docker.sock"
    proc = None
    try:
        _run("ip", "netns", "add", ns)
        _run("ip", "link", "add", link, "type", "veth", "peer", "name", f"{tag}p")
        _run("ip", "link", "set", f"{tag}p", "netns", ns)
        _run("ip", "addr", "add", f"{SUBNET}.1/24", "dev", link)
        _run("ip", "link", "set", link, "up")
        _run("ip", "-n", ns, "link", "set", f"{tag}p", "name", "eth0")
        _run("ip", "-n", ns, "addr", "add", f"{SUBNET}.2/24", "dev", "eth0")
        _run("ip", "-n", ns, "link", "set", "eth0", "up")
        _run("ip", "-n", ns, "link", "set", "lo", "up")
        folder.mkdir(parents=True)
        log = open(f"/tmp/{tag}-dockerd.log", "w")  # noqa: SIM115 (kept open for the daemon)
        proc = subprocess.Popen(
            ["nsenter", f"--net=/var/run/netns/{ns}", "dockerd", "--data-root", str(data), "--exec-root",
             str(folder / "exec"), "--pidfile", str(folder / "dockerd.pid"), "-H", sock,
             "--storage-driver=overlay2"], stdout=log, stderr=subprocess.STDOUT)  # fmt: skip
        deadline = time.monotonic() + 60
        while docker("info", host=sock, check=False).returncode != 0:
            if proc.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f"the second dockerd did not start; see /tmp/{tag}-dockerd.log")
            time.sleep(0.5)
        yield sock
    finally:
        if proc is not None:
            leftover = docker("ps", "-aq", host=sock, check=False).stdout.split()
            if leftover:
                docker("rm", "-f", *leftover, host=sock, check=False, timeout=120)
            proc.terminate()
            with contextlib.suppress(subprocess.TimeoutExpired):
                proc.wait(60)
        _run("ip", "link", "del", link, check=False)
        _run("ip", "netns", "del", ns, check=False)
        shutil.rmtree(data, ignore_errors=True)
        shutil.rmtree(folder, ignore_errors=True)


@contextlib.contextmanager
def two_node_swarm(image: str) -> Iterator[Nodes]:
    """This engine (manager, labelled for the world) and a second one (worker), both with `image`."""
    tag = f"swn{uuid.uuid4().hex[:5]}"
    with _second_engine(tag) as worker_host:
        docker("swarm", "init", "--advertise-addr", f"{SUBNET}.1")
        try:
            token = docker("swarm", "join-token", "-q", "worker").stdout.strip()
            docker("swarm", "join", "--advertise-addr", f"{SUBNET}.2", "--token", token, f"{SUBNET}.1:2377",
                   host=worker_host)  # fmt: skip
            manager = docker("info", "-f", "{{.Swarm.NodeID}}").stdout.strip()
            worker = docker("info", "-f", "{{.Swarm.NodeID}}", host=worker_host).stdout.strip()
            docker("node", "update", "--label-add", WORLD_LABEL, manager)
            save = subprocess.Popen(["docker", "save", image], stdout=subprocess.PIPE)
            docker("load", "-q", host=worker_host, stdin=save.stdout, timeout=600)
            save.wait(60)
            yield Nodes(manager, worker, worker_host)
        finally:
            docker("swarm", "leave", "--force", host=worker_host, check=False)
            docker("swarm", "leave", "--force", check=False)
            docker("network", "rm", "docker_gwbridge", check=False)  # made by `swarm init`, left by `leave`
