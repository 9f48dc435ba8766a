"""Secure runs at a real router: zenoh's own login, access control (swarm/core/acl.py) and TLS.

What the router refuses never reaches the world: no session without the
run's credentials, no put of an agent process on another's keys or on the
world's; a secure run ends exactly as a plain one."""

from __future__ import annotations

import base64
import json
import os
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from swarm.core import credentials, kubernetes_secrets
from swarm.core.bus import open_bridge, open_client, open_router
from swarm.core.credentials import MONITOR, ROUTER, WORLD, agent_name, identity_in
from swarm.core.wire import Keys
from swarm.engines.grid import Engine
from swarm.scenario import load_scenario
from tests.distributed import ServerThread, free_endpoint, start_agents, stop
from world_server.grid.face import wire as proto

KEYS = Keys("sec")
COLD_START = 240.0  # s the world waits for its agents: a cold cache compiles their kernels first, under load


@pytest.fixture(scope="module")
def creds(tmp_path_factory) -> Path:
    return credentials.make(tmp_path_factory.mktemp("creds"), 3)


class Heard:
    """Every sample on the run's keys, as the world's side receives them."""

    def __init__(self, session):
        self.keys: list[str] = []
        self.lock = threading.Lock()
        self.sub = session.declare_subscriber(f"{KEYS.prefix}/**", self._on)

    def _on(self, sample) -> None:
        with self.lock:
            self.keys.append(str(sample.key_expr))

    def settled(self, wait: float = 0.5) -> set[str]:
        time.sleep(wait)
        with self.lock:
            return set(self.keys)


STAY = np.array([[4, 0, 0, 0, 0, 0, 0, 0]], dtype=np.int64)


def _ends_as_the_engine(world: ServerThread, procs: list, expected: dict, closing=(), meanwhile=lambda: None) -> None:
    """`meanwhile()`, then the world's run and its agent processes end well, with the engine's result and
    nothing refused; the processes and sessions (`closing`) are stopped either way."""
    try:
        meanwhile()
        summary = world.join(timeout=COLD_START + 120)
        for p in procs:
            assert p.wait(timeout=30) == 0, p.stderr.read().decode()[-2000:]
    finally:
        for session in closing:
            session.close()
        stop(procs)
        world.close()
    assert summary["rejected_messages"] == 0 and summary["agents_lost"] == 0
    for key in ("iterations", "delivered", "total", "finished", "explored_cells"):
        assert summary[key] == expected[key], key


def _wrong_password(creds: Path, tmp_path: Path) -> credentials.Identity:
    copy = shutil.copytree(creds / agent_name(1), tmp_path / "guessed")
    (copy / "identity.json").write_text(json.dumps({"user": agent_name(1), "password": "guessed"}))
    return credentials.load(copy)


def test_no_or_wrong_credentials_are_refused_and_never_reach_the_world(creds, tmp_path):
    endpoint = free_endpoint()
    router = open_router(endpoint, identity_in(creds, ROUTER))  # the world hosts the router
    try:
        heard = Heard(router)
        with pytest.raises(ConnectionError, match="start `swarm world` first"):
            open_client(endpoint, timeout=1.0)
        with pytest.raises(ConnectionError, match="refused the credentials of 'agent1'"):
            open_client(endpoint, timeout=1.0, identity=_wrong_password(creds, tmp_path))
        assert heard.settled(0.1) == set()
        agent = open_client(endpoint, timeout=5.0, identity=identity_in(creds, agent_name(1)))
        agent.put(KEYS.act(agent_name(1)), b"mine")
        assert heard.settled() == {KEYS.act(agent_name(1))}
        agent.close()
    finally:
        router.close()


def test_an_agent_process_puts_only_on_its_own_keys_through_a_bare_router(creds):
    endpoint = free_endpoint()
    router = open_router(endpoint, identity_in(creds, ROUTER))  # `swarm router --credentials DIR/router`
    world = open_client(endpoint, timeout=5.0, identity=identity_in(creds, WORLD))
    agent = open_client(endpoint, timeout=5.0, identity=identity_in(creds, agent_name(1)))
    monitor = open_client(endpoint, timeout=5.0, identity=identity_in(creds, MONITOR))
    try:
        heard = Heard(world)
        spied: list[bytes] = []
        agent.declare_subscriber(KEYS.obs(agent_name(2)), lambda s: spied.append(s.payload.to_bytes()))
        mine = [KEYS.act(agent_name(1)), KEYS.mark(agent_name(1)), KEYS.plan(agent_name(1))]
        publisher = agent.declare_publisher(mine[0])
        time.sleep(0.3)
        other = agent_name(2)
        for key in (KEYS.act(other), KEYS.mark(other), KEYS.plan(other), KEYS.record(other), KEYS.obs(other),
                    KEYS.state, KEYS.join, KEYS.alive(0)):  # fmt: skip
            agent.put(key, b"forged")
        monitor.put(mine[0], b"forged")
        world.put(KEYS.obs(other), b"for agent2 only")
        publisher.put(b"mine")
        for key in mine[1:]:
            agent.put(key, b"mine")
        assert heard.settled() == {*mine, KEYS.obs(other)}  # the world's own put, heard by its own subscriber
        assert b"for agent2 only" not in spied  # (its own forged put comes back to it inside its session)
    finally:
        for s in (monitor, agent, world, router):
            s.close()


def test_tls_refuses_a_client_without_the_runs_certificate(creds, tmp_path):
    endpoint = free_endpoint().replace("tcp/", "tls/")
    foreign = credentials.make(tmp_path / "other", 1)  # another run's CA: its agent1 has the right name
    router = open_router(endpoint, identity_in(creds, ROUTER))
    try:
        heard = Heard(router)
        for stranger in (None, identity_in(foreign, agent_name(1))):
            with pytest.raises(ConnectionError):
                open_client(endpoint, timeout=1.0, identity=stranger)
        agent = open_client(endpoint, timeout=5.0, identity=identity_in(creds, agent_name(1)))
        agent.put(KEYS.act(agent_name(2)), b"forged")
        agent.put(KEYS.act(agent_name(1)), b"mine")
        assert heard.settled() == {KEYS.act(agent_name(1))}
        agent.close()
    finally:
        router.close()


def test_a_secure_world_never_sees_a_forged_action_and_ends_as_the_engine(creds):
    scenario = load_scenario("setup2").with_overrides(agents=2, seed=21)
    engine = Engine(scenario)
    expected = engine.run().summary
    endpoint = free_endpoint()
    world = ServerThread(scenario, "sec", endpoint, deadline=10.0, start_timeout=COLD_START,
                         identity=identity_in(creds, ROUTER)).start()  # fmt: skip
    procs = start_agents(endpoint, "sec", scenario.controller, 2, credentials=creds)
    forger = open_client(endpoint, timeout=30.0, identity=identity_in(creds, agent_name(3)))  # a spare process

    def forge() -> None:
        for _ in range(200):  # a plain run counts each: "names an agent of another process"
            forger.put(KEYS.act(agent_name(1)), proto.actions(0, [0], STAY, [False]))
            forger.put(KEYS.act(agent_name(2)), b"\x00\xffgarbage")

    _ends_as_the_engine(world, procs, expected, closing=(forger,), meanwhile=forge)


def test_swarm_up_secure_over_tls_ends_as_the_engine(tmp_path):
    scenario = load_scenario("setup2").with_overrides(agents=2, seed=9)
    expected = Engine(scenario).run().summary
    up = subprocess.run([sys.executable, "-m", "swarm", "up", "setup2", "--agents", "2", "--seed", "9", "--secure",
                         "--listen", free_endpoint().replace("tcp/", "tls/"), "--no-record", "--json"],
                        capture_output=True, text=True, timeout=300, cwd=tmp_path)  # fmt: skip
    assert up.returncode == 0, up.stderr[-3000:]
    summary = json.loads(up.stdout)
    for key in ("iterations", "delivered", "total", "finished", "explored_cells"):
        assert summary[key] == expected[key], key
    assert summary["rejected_messages"] == 0


def test_credentials_are_private_and_a_bad_folder_is_one_line(creds, tmp_path):
    for name in (ROUTER, agent_name(1)):
        assert (creds / name / "key.pem").stat().st_mode & 0o777 == 0o600
        assert (creds / name / "identity.json").stat().st_mode & 0o777 == 0o600
    assert (creds / ROUTER / "users.txt").stat().st_mode & 0o777 == 0o600
    assert not (creds / agent_name(1) / "users.txt").exists()  # an agent holds its own password only
    assert not credentials.is_pool(creds)  # a run's folder of agent<i>: no agent claims from it by mistake
    bad = subprocess.run([sys.executable, "-m", "swarm", "agent", "--credentials", str(tmp_path), "--connect",
                          free_endpoint()], capture_output=True, text=True, timeout=60)  # fmt: skip
    assert bad.returncode == 2
    assert bad.stderr.strip().splitlines() == [f"swarm: error: {tmp_path}: not a credentials folder "
                                               "(no readable identity.json)"]  # fmt: skip


def test_swarm_up_secure_with_an_endpoint_it_cannot_read_is_one_line(tmp_path):
    """The router's certificate names the host of --listen: one that names none stops before anything starts."""
    command = [sys.executable, "-m", "swarm", "up", "setup2", "--agents", "2", "--secure", "--listen", "garbage"]
    up = subprocess.run(command, capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert up.returncode == 2
    assert up.stderr.strip().splitlines() == [
        "swarm: error: --listen 'garbage': expected PROTOCOL/NAME:PORT, e.g. tcp/router:7447"
    ]


CLAIM = ("import sys\nfrom swarm.core.credentials import claim\n"
         "print(claim(sys.argv[1], *map(int, sys.argv[2:])).name, flush=True)\n"
         "sys.stdin.read()\n")  # holds its identity until its stdin closes  # fmt: skip


def _claimer(pool: Path, *slot: int, started: list[subprocess.Popen]) -> subprocess.Popen:
    """A process that claims an identity of `pool` (agent<slot>, given one), says which, and holds it; in `started`."""
    started.append(subprocess.Popen([sys.executable, "-c", CLAIM, str(pool), *map(str, slot)], stdin=subprocess.PIPE,
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True))  # fmt: skip
    return started[-1]


def test_replicas_claim_an_identity_each_and_a_killed_ones_is_free_again(tmp_path):
    pool = credentials.make(tmp_path, 2, pool=True) / credentials.POOL
    assert not (tmp_path / agent_name(1)).exists() and (pool / agent_name(2) / "key.pem").is_file()
    assert pool.stat().st_mode & 0o777 == 0o700 and credentials.is_pool(pool)
    started: list[subprocess.Popen] = []
    try:
        first = _claimer(pool, started=started)
        killed = first.stdout.readline().strip()
        kept = _claimer(pool, started=started).stdout.readline().strip()
        assert {killed, kept} == {agent_name(1), agent_name(2)}
        third = _claimer(pool, started=started)
        assert third.wait(timeout=60) == 1
        assert third.stderr.read().strip().splitlines()[-1] == (
            f"swarm.core.credentials.CredentialsError: {pool}: all 2 agent identities are held by running processes; "
            "make a bigger pool with `swarm credentials DIR --pool --agent-processes N`"
        )
        first.kill()  # kill -9: the kernel lets its lock go
        first.wait(timeout=30)
        assert _claimer(pool, started=started).stdout.readline().strip() == killed
    finally:
        stop(started)


def test_a_numbered_replica_takes_its_own_identity_or_says_why_not(tmp_path):
    """Across hosts no lock is shared: replica N (Docker Swarm's task slot) is the pool's agentN."""
    pool = credentials.make(tmp_path, 2, pool=True) / credentials.POOL
    started: list[subprocess.Popen] = []
    try:
        assert _claimer(pool, 2, started=started).stdout.readline().strip() == agent_name(2)
        for slot, why in ((2, f"{agent_name(2)} is held by another running process (replica 2 twice?)"),
                          (3, f"no identity {agent_name(3)} for replica 3")):  # fmt: skip
            refused = _claimer(pool, slot, started=started)
            assert refused.wait(timeout=60) == 1 and why in refused.stderr.read()
    finally:
        stop(started)
    assert _refused_agent(pool, SWARM_AGENT_SLOT="x") == [
        "swarm: error: $SWARM_AGENT_SLOT is 'x': expected the replica's number, e.g. {{.Task.Slot}}"
    ]


def _refused_agent(pool: Path, **env: str) -> list[str]:
    """What `swarm agent --credentials POOL` says, with `env`, as it stops with status 2."""
    refused = subprocess.run([sys.executable, "-m", "swarm", "agent", "--credentials", str(pool), "--connect",
                              free_endpoint()], capture_output=True, text=True, timeout=60,
                             env={**os.environ, **env})  # fmt: skip
    assert refused.returncode == 2, refused.stderr
    return refused.stderr.strip().splitlines()


def test_a_kubernetes_pod_takes_the_identity_after_its_index_from_the_flat_pool(tmp_path):
    """A Secret's keys hold no '/': the pool's agent<i>.<file> files, claimed by index + 1 or by lock."""
    creds = credentials.make(tmp_path / "creds", 3)
    pool = _mounted(kubernetes_secrets.secrets(creds)[-1], tmp_path / "pool")
    assert credentials.is_pool(pool)
    assert [name for name, _, _ in credentials.pool_members(pool)] == [agent_name(i) for i in (1, 2, 3)]
    started: list[subprocess.Popen] = []
    try:
        assert _claimer(pool, 2, started=started).stdout.readline().strip() == agent_name(2)
        assert _claimer(pool, started=started).stdout.readline().strip() == agent_name(1)  # the first free one
    finally:
        stop(started)
    flat = credentials.claim(pool, 3)
    assert (flat.name, flat.cert.read_bytes()) == (agent_name(3), (creds / agent_name(3) / "cert.pem").read_bytes())
    assert _refused_agent(pool, SWARM_AGENT_INDEX="-1") == [
        "swarm: error: $SWARM_AGENT_INDEX is '-1': expected the replica's number, e.g. a StatefulSet pod's index"
    ]
    assert _refused_agent(pool, SWARM_AGENT_INDEX="") == [
        "swarm: error: $SWARM_AGENT_INDEX is '': expected the replica's number, e.g. a StatefulSet pod's index (a "
        "pod's index label needs Kubernetes 1.28 or newer)"
    ]


def _mounted(secret: dict, where: Path) -> Path:
    """A Secret as the kubelet mounts it: a file per key (mode 0400), each a link through `..data`, itself a
    link to the folder of the Secret's current version."""
    (where / "..2026_12_07_00_00_00.000000001").mkdir(parents=True)
    (where / "..data").symlink_to("..2026_12_07_00_00_00.000000001")
    for key, value in secret["data"].items():
        (where / "..data" / key).write_bytes(base64.b64decode(value))
        (where / "..data" / key).chmod(0o400)
        (where / key).symlink_to(Path("..data") / key)
    return where


def test_a_secure_run_from_the_kubernetes_secrets_ends_as_the_engine(tmp_path):
    """deploy/k8s-secure's wiring: the Secrets of `swarm credentials --kubernetes` mounted as the kubelet
    mounts them; a router over TLS with the router's, the world joining it with the world's, and two agent
    pods that take their identities from the one pool Secret by their StatefulSet index."""
    creds = credentials.make(tmp_path / "creds", 2)
    mounts = {s["metadata"]["name"]: _mounted(s, tmp_path / s["metadata"]["name"])
              for s in kubernetes_secrets.secrets(creds)}  # fmt: skip
    scenario = load_scenario("setup2").with_overrides(agents=2, seed=5)
    expected = Engine(scenario).run().summary
    endpoint = free_endpoint().replace("tcp/", "tls/")
    router = open_router(endpoint, credentials.load(mounts[kubernetes_secrets.secret_name(ROUTER)]))
    world = ServerThread(scenario, "k8s", endpoint, connect=endpoint, deadline=10.0, start_timeout=COLD_START,
                         identity=credentials.load(mounts[kubernetes_secrets.secret_name(WORLD)])).start()  # fmt: skip
    cmd = [sys.executable, "-m", "swarm", "agent", "--connect", endpoint, "--run-id", "k8s", "--controller",
           scenario.controller, "--credentials", str(mounts[kubernetes_secrets.POOL_SECRET])]  # fmt: skip
    procs = [subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                              env={**os.environ, "SWARM_AGENT_INDEX": str(index)}) for index in (1, 0)]  # fmt: skip
    _ends_as_the_engine(world, procs, expected, closing=(router,))
    said = [p.stderr.read().decode().splitlines()[0] for p in procs]
    assert [line.split(" (claimed")[0] for line in said] == [f"swarm: this agent process is {agent_name(i)}"
                                                            for i in (2, 1)]  # fmt: skip


def test_replicas_from_a_pool_run_a_secure_run_as_the_engine(tmp_path):
    """Identical `swarm agent --credentials POOL` commands, as compose's replicas run them."""
    creds = credentials.make(tmp_path, 2, pool=True)
    scenario = load_scenario("setup2").with_overrides(agents=2, seed=5)
    expected = Engine(scenario).run().summary
    endpoint = free_endpoint()
    world = ServerThread(scenario, "pool", endpoint, deadline=10.0, start_timeout=COLD_START,
                         identity=identity_in(creds, ROUTER)).start()  # fmt: skip
    cmd = [sys.executable, "-m", "swarm", "agent", "--connect", endpoint, "--run-id", "pool", "--controller",
           scenario.controller, "--credentials", str(creds / credentials.POOL)]  # fmt: skip
    procs = [subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE) for _ in range(2)]
    _ends_as_the_engine(world, procs, expected)


@pytest.mark.parametrize("meshed", ["linked", "bridged"])
def test_a_run_across_two_secure_routers_over_tls_ends_as_the_engine(creds, meshed):
    """The world hosts router A; router B, meshed to A over TLS (by its own link, or through a bridge, as
    `swarm router --mesh` links routers found after they opened), serves the agent processes (a second
    host's router): each router lets in only what its rules allow, and they carry the rest to each other."""
    scenario = load_scenario("setup2").with_overrides(agents=2, seed=13)
    expected = Engine(scenario).run().summary
    near, far = (free_endpoint().replace("tcp/", "tls/") for _ in range(2))
    world = ServerThread(scenario, "sec", near, deadline=10.0, start_timeout=COLD_START,
                         identity=identity_in(creds, ROUTER)).start()  # fmt: skip
    second = open_router(far, identity_in(creds, ROUTER), connect=[near] if meshed == "linked" else None)
    closing = [second]
    if meshed == "bridged":
        closing.append(open_bridge(near, far, identity_in(creds, ROUTER)))
    procs = start_agents(far, "sec", scenario.controller, 2, credentials=creds)
    forger = open_client(far, timeout=30.0, identity=identity_in(creds, agent_name(3)))
    watcher = open_client(near, timeout=30.0, identity=identity_in(creds, WORLD))  # on A, beside the world
    heard: list[bytes] = []
    watcher.declare_subscriber(KEYS.act(agent_name(1)), lambda sample: heard.append(sample.payload.to_bytes()))
    forged = proto.actions(2**40, [0], STAY, [False])  # (for a tick the run never reaches: known by it)

    def forge() -> None:
        deadline = time.monotonic() + COLD_START
        while not heard:  # agent1's own actions cross from B to A: the route is there
            assert time.monotonic() < deadline, "no action of agent1 reached router A"
            time.sleep(0.05)
        for _ in range(200):  # refused at router B: never crosses to A
            forger.put(KEYS.act(agent_name(1)), forged)

    _ends_as_the_engine(world, procs, expected, closing=(forger, watcher, *closing[::-1]), meanwhile=forge)
    assert heard and forged not in heard


def test_a_secure_mesh_over_plain_tcp_is_refused_in_one_line(creds):
    router = subprocess.run([sys.executable, "-m", "swarm", "router", "--listen", free_endpoint(), "--mesh",
                             "tcp/router:7447", "--credentials", str(creds / ROUTER)],
                            capture_output=True, text=True, timeout=60)  # fmt: skip
    assert router.returncode == 2
    assert router.stderr.strip().splitlines() == [
        "swarm: error: a secure mesh of routers needs TLS links, which show each router's certificate: give "
        "--listen tls/... and --mesh tls/..."
    ]
