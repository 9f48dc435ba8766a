"""`docker compose up swarm` against a real Docker engine (compose.yaml, Dockerfile), and
`docker stack deploy` of stack.yaml on a real two-node Docker Swarm.

The image is built from a debootstrapped base and a host-built wheelhouse (no
registry is reachable here).  One run of 3 agent containers goes to the end:
the monitor's summary and its exit code, and the recording in ./runs.  A second,
longer run is scaled from 3 to 5 agents while the world ticks: the two new
containers join it.  Debian ships compose v1 (`docker-compose`), whose
`--exit-code-from` is broken on Python 3.11, so exit codes are read with
`docker inspect`.  Then the same image runs as a stack on this engine and a second one
(tests/docker_swarm.py): a router on each node, meshed over the overlay network, the world
on the labelled node, agents on both; the run equals the compose run.  Everything is torn
down, run or fail, the app image too.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time
import urllib.request
import uuid

import pytest

from tests.distributed import free_endpoint
from tests.docker_engine import (
    BASE_TAG,
    ROOT,
    build_base,
    build_cached_stages,
    build_wheelhouse,
    docker_engine,
    why_no_engine,
)
from tests.docker_swarm import Nodes, docker, two_node_swarm, why_no_second_node

pytestmark = pytest.mark.timeout(900)

reason = why_no_engine()
if reason is not None:
    pytest.skip(f"compose smoke test needs a Docker engine: {reason}", allow_module_level=True)


class Compose:
    def __init__(self, project: str, **settings: str):
        self.project = project
        self.env = {**os.environ, "BASE": BASE_TAG, **settings}

    def __call__(self, *args: str, timeout: float = 300, check: bool = True) -> subprocess.CompletedProcess:
        return subprocess.run(["docker-compose", "-p", self.project, *args], cwd=ROOT, env=self.env, text=True,
                              capture_output=True, timeout=timeout, check=check)  # fmt: skip

    def exit_code(self, service: str) -> int:
        (cid,) = self("ps", "-q", service).stdout.split()
        out = subprocess.run(["docker", "inspect", "-f", "{{.State.ExitCode}}", cid], capture_output=True, text=True)
        return int(out.stdout.strip())

    def status(self) -> dict | None:
        """The world's info, asked from the host through the router's published port."""
        out = subprocess.run(
            [sys.executable, "-m", "swarm", "status", "--json", "--connect", f"tcp/127.0.0.1:{self.env['ROUTER_PORT']}",
             "--run-id", self.env["RUN_ID"]], capture_output=True, text=True, timeout=60)  # fmt: skip
        return json.loads(out.stdout) if out.returncode == 0 else None


@pytest.fixture(scope="module")
def compose():
    project = f"swarmtest{uuid.uuid4().hex[:6]}"
    ports = {name: free_endpoint().rsplit(":", 1)[1] for name in ("ROUTER_PORT", "VIEWER_PORT", "GRPC_PORT")}
    with docker_engine():
        build_base()
        build_wheelhouse()
        c = Compose(project, **ports)
        try:
            started = time.monotonic()
            build_cached_stages()  # the dependencies: from the cache of earlier runs unless they changed
            deps_built = time.monotonic()
            c("build", "router", timeout=900)  # every service runs this one image (swarm:local)
            took, deps = time.monotonic() - started, deps_built - started
            print(f"image built in {took:.0f} s (dependency stages {deps:.0f} s, the project {took - deps:.0f} s)")
            yield c
        finally:
            c("down", "--remove-orphans", "--timeout", "5", check=False, timeout=300)
            # the app image and the layers its builds left: each run would otherwise keep ~4 GB on the disk.
            # The tagged dependency stages (tests/docker_engine.py CACHED_STAGES) stay for the next run;
            # the ones their tags moved from are dangling and go here.
            subprocess.run(["docker", "rmi", "-f", "swarm:local"], capture_output=True, timeout=300)
            subprocess.run(["docker", "image", "prune", "-f"], capture_output=True, timeout=300)
            for wheel in (ROOT / "wheels").glob("*.whl"):
                wheel.unlink()


def test_compose_up_swarm_runs_to_the_end_and_records(compose):
    run_id = f"smoke{uuid.uuid4().hex[:6]}"
    compose.env.update(RUN_ID=run_id, SCENARIO="open", SEED="1", AGENTS="3", MAX_AGENTS="3")
    started = time.monotonic()
    out = compose("up", "--scale", "agent=3", "swarm", timeout=600)
    took = time.monotonic() - started
    log = compose("logs", "--no-color", "swarm").stdout
    assert compose.exit_code("swarm") == 0, log
    assert "open: cmarking x3, seed 1: finished after 2367 iterations" in log, out.stdout + log  # = swarm run
    assert "delivered 6000/6000" in log
    assert "agents joined 3 (at most 3 at once), lost 0" in log
    recordings = sorted((ROOT / "runs").glob(f"{run_id}-*.rrd"))
    assert len(recordings) == 1
    try:
        from swarm.review.report import read_recording, summary_from

        summary = summary_from(read_recording(recordings[0]))
        assert (summary["iterations"], summary["delivered"], summary["agents_peak"]) == (2367, 6000, 3)
    finally:
        recordings[0].unlink()
    with urllib.request.urlopen(f"http://127.0.0.1:{compose.env['VIEWER_PORT']}", timeout=10) as page:
        assert page.status == 200  # the web viewer, published on the host
    assert took < 120, f"`up swarm` with images built took {took:.0f} s"
    print(f"docker compose up swarm (images built): {took:.1f} s")


def _claimed(log: str) -> list[str]:
    """The identities agent replicas say they took from a pool (`swarm agent`'s first line), sorted."""
    return sorted(line.split(" is ")[1].split()[0] for line in log.splitlines() if "this agent process is" in line)


def test_compose_secure_over_tls_gives_each_agent_replica_its_own_identity(compose, tmp_path):
    """compose.secure.yaml with LINK=tls: every link TLS with the run's certificates, the replicas each
    claim an identity of the pool, and the run ends as the plain one above."""
    from swarm.core import credentials

    creds = credentials.make(tmp_path / "creds", 3, hosts=("router",), pool=True)
    run_id = f"secure{uuid.uuid4().hex[:6]}"
    compose.env.update(RUN_ID=run_id, SCENARIO="open", SEED="1", AGENTS="3", MAX_AGENTS="3", LINK="tls",
                       CREDENTIALS=str(creds))  # fmt: skip
    secure = ("-f", "compose.yaml", "-f", "compose.secure.yaml")
    try:
        up = compose(*secure, "up", "--scale", "agent=3", "swarm", timeout=600, check=False)
        log = compose(*secure, "logs", "--no-color", "swarm").stdout
        agents = compose(*secure, "logs", "--no-color", "agent").stdout
        assert compose.exit_code("swarm") == 0, up.stdout[-3000:] + up.stderr[-3000:] + log + agents[-3000:]
        assert "open: cmarking x3, seed 1: finished after 2367 iterations" in log, log  # = the plain run
        assert "agents joined 3 (at most 3 at once), lost 0" in log, log
        assert _claimed(agents) == ["agent1", "agent2", "agent3"], agents[-3000:]
    finally:
        compose(*secure, "down", "--remove-orphans", "--timeout", "5", check=False, timeout=300)
        for key in ("LINK", "CREDENTIALS"):
            compose.env.pop(key, None)
        for recording in (ROOT / "runs").glob(f"{run_id}-*.rrd"):
            recording.unlink()


def test_compose_runs_an_arena_with_the_carrot_controller(compose):
    """SCENARIO=zmaze CONTROLLER=carrot docker compose up swarm: 64 slots, the 2 agents that join drive."""
    run_id = f"arena{uuid.uuid4().hex[:6]}"
    compose.env.update(RUN_ID=run_id, SCENARIO="zmaze", CONTROLLER="carrot", SEED="1", AGENTS="2")
    compose.env.pop("MAX_AGENTS", None)
    try:
        up = compose("up", "--scale", "agent=2", "swarm", timeout=600, check=False)
        world_log = compose("logs", "--no-color", "world").stdout
        assert up.returncode == 0, up.stdout[-2000:] + up.stderr[-2000:] + world_log[-3000:]
        log = compose("logs", "--no-color", "swarm").stdout
        assert compose.exit_code("swarm") == 0, up.stdout[-3000:] + up.stderr[-3000:] + log
        assert "zmaze: carrot x2, seed 1, noise low: finished" in log and "reached 2/2" in log, log
    finally:
        compose.env["CONTROLLER"] = "cmarking"
        for recording in (ROOT / "runs").glob(f"{run_id}-*.rrd"):
            recording.unlink()


def test_compose_runs_a_users_controller_package_from_an_image_built_from_ours(compose, tmp_path):
    """docs/controllers.md, In containers: an image FROM swarm:local with the flocking example package
    installed (from its wheel, built on the host: containers here reach no package index) runs the
    package's controller, by its entry point's name, in the world and in every agent container."""
    import shutil

    wheels, context = tmp_path / "wheels", tmp_path / "context"
    package = ROOT / "examples" / "flocking"
    built = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-w", str(wheels), str(package)],
                           capture_output=True, text=True, timeout=300)  # fmt: skip
    assert built.returncode == 0, built.stdout[-2000:] + built.stderr[-2000:]
    (wheel,) = wheels.glob("*.whl")
    context.mkdir()
    for file in (wheel, package / "flock.toml"):
        shutil.copy(file, context / file.name)
    install = f"pip install --no-cache-dir --no-index --no-deps /src/{wheel.name}"
    (context / "Dockerfile").write_text(f"FROM swarm:local\nCOPY {wheel.name} flock.toml /src/\nRUN {install}\n")
    image, run_id = f"swarm-flocking-{uuid.uuid4().hex[:6]}:local", f"flock{uuid.uuid4().hex[:6]}"
    built = subprocess.run(["docker", "build", "-t", image, str(context)], capture_output=True, text=True, timeout=600)
    assert built.returncode == 0, built.stderr[-3000:]
    saved = dict(compose.env)
    compose.env.update(IMAGE=image, RUN_ID=run_id, SCENARIO="/src/flock.toml", CONTROLLER="flocking", SEED="2",
                       AGENTS="2", MAX_AGENTS="2")  # fmt: skip
    try:
        up = compose("up", "--scale", "agent=2", "swarm", timeout=600, check=False)
        log = compose("logs", "--no-color", "swarm").stdout
        assert up.returncode == 0 and compose.exit_code("swarm") == 0, up.stdout[-3000:] + up.stderr[-3000:] + log
        assert "flock: flocking x2, seed 2, noise low: finished after 1500 ticks" in log, log
        assert "agents joined 2" in log and "lost 0" in log, log
    finally:
        compose("down", "--remove-orphans", "--timeout", "5", check=False, timeout=300)
        compose.env.clear()
        compose.env.update(saved)
        subprocess.run(["docker", "rmi", "-f", image], capture_output=True, timeout=300)
        for recording in (ROOT / "runs").glob(f"{run_id}-*.rrd"):
            recording.unlink()


def test_scaling_a_running_world_from_3_to_5_agents(compose):
    run_id = f"scale{uuid.uuid4().hex[:6]}"
    compose.env.update(RUN_ID=run_id, SCENARIO="setup1", SEED="1", AGENTS="3", MAX_AGENTS="5")
    compose("up", "-d", "--scale", "agent=3", "agent", timeout=600)
    deadline = time.monotonic() + 120
    while (info := compose.status()) is None or info["tick"] < 50:
        assert time.monotonic() < deadline, "the world did not start ticking with 3 agents"
        time.sleep(0.5)
    assert info["agents_alive"] == 3 and not info["ended"]
    compose("up", "-d", "--scale", "agent=5", "--no-recreate", "agent", timeout=600)
    deadline = time.monotonic() + 120
    while (info := compose.status()) is None or info["agents_alive"] < 5:
        assert info is None or not info["ended"], f"the run ended before the new agents joined: {info}"
        assert time.monotonic() < deadline, f"the new agents did not join: {info}"
        time.sleep(0.5)
    joined_at = info["tick"]
    compose("up", "--scale", "agent=5", "swarm", timeout=300)  # without --scale: back to AGENTS
    log = compose("logs", "--no-color", "swarm").stdout
    assert compose.exit_code("swarm") == 0, log
    assert "finished after" in log and "agents joined 5 (at most 5 at once), lost 0" in log, log
    for recording in (ROOT / "runs").glob(f"{run_id}-*.rrd"):
        recording.unlink()
    print(f"5 agents active from tick {joined_at}")


@pytest.fixture(scope="module")
def swarm_nodes(compose):
    """A two-node Docker Swarm of the test's engine (the world's node) and a second one, both with the image."""
    if (reason := why_no_second_node()) is not None:
        pytest.skip(f"a second Docker engine cannot be started here: {reason}")
    if docker("info", "-f", "{{.Swarm.LocalNodeState}}").stdout.strip() != "inactive":
        pytest.skip("the engine is already part of a swarm; the test needs one it can make and leave")
    started = time.monotonic()
    with two_node_swarm("swarm:local") as nodes:
        print(f"second engine started, swarm made, image copied: {time.monotonic() - started:.0f} s")
        yield nodes


def _logs(service: str) -> str:
    """What the service's tasks wrote, stdout and stderr (the docker client splits them as they were)."""
    out = docker("service", "logs", "--raw", service, check=False)
    return out.stdout + out.stderr


def _task_nodes(service: str) -> set[str]:
    tasks = docker("service", "ps", "-q", service).stdout.split()
    return set(docker("inspect", "-f", "{{.NodeID}}", *tasks).stdout.split())


def _finished(service: str, timeout: float) -> bool:
    """Whether the service's task completed (exit 0) within `timeout`; False if it failed for good."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        states = docker("service", "ps", "--format", "{{.CurrentState}}", service, check=False).stdout.split("\n")
        if any(s.startswith("Complete") for s in states):
            return True
        time.sleep(1)
    return False


def _stack_down(stack: str, nodes: Nodes) -> None:
    docker("stack", "rm", stack, check=False)
    deadline = time.monotonic() + 90
    while nodes.stack_containers(stack) and time.monotonic() < deadline:
        time.sleep(1)
    docker("volume", "rm", f"{stack}_state", check=False)


def _stack_run(nodes: Nodes, tmp_path, files: tuple[str, ...], **settings: str) -> dict[str, str]:
    """Deploy `files` (stack.yaml first) as a stack of its own for a run of `open` with 3 agents, check what
    every deployment must give (the compose run's result, a router on each node, the world on the labelled
    one, agents on both, the recording), tear it down: the services' logs, by service."""
    stack, run_id = f"swarmstack{uuid.uuid4().hex[:6]}", f"stack{uuid.uuid4().hex[:6]}"
    ports = {name: free_endpoint().rsplit(":", 1)[1] for name in ("ROUTER_PORT", "VIEWER_PORT", "GRPC_PORT")}
    env = {**os.environ, **ports, "IMAGE": "swarm:local", "RUN_ID": run_id, "SCENARIO": "open", "SEED": "1",
           "AGENTS": "3", "MAX_AGENTS": "3", "RUNS": str(tmp_path), **settings}  # fmt: skip
    started = time.monotonic()
    try:
        compose_files = [arg for f in files for arg in ("-c", f)]
        docker("stack", "deploy", "--detach=true", "--resolve-image", "never", *compose_files, stack, cwd=ROOT,
               env=env)  # fmt: skip
        done = _finished(f"{stack}_swarm", timeout=300)
        took = time.monotonic() - started
        logs = {service: _logs(f"{stack}_{service}") for service in ("swarm", "router", "world", "agent")}
        log = logs["swarm"]
        if not done:
            for service in ("router", "world", "agent"):
                print(logs[service][-3000:])
        assert done, f"the monitor did not finish: {log[-3000:]}"
        assert "open: cmarking x3, seed 1: finished after 2367 iterations" in log, log  # = swarm run, = compose
        assert "delivered 6000/6000" in log, log
        # every replica lost is replaced (restart_policy), never more than 3 at once: under load in CI one replica
        # has been seen to join, be lost and be replaced while the worker's agents waited (cause not traced)
        joined, lost = map(int, re.search(r"agents joined (\d+) \(at most 3 at once\), lost (\d+)", log).groups())
        assert joined - lost == 3, log
        assert _task_nodes(f"{stack}_router") == {nodes.manager, nodes.worker}  # global: one each
        assert _task_nodes(f"{stack}_world") == {nodes.manager}  # the labelled node
        assert _task_nodes(f"{stack}_agent") == {nodes.manager, nodes.worker}
        (recording,) = tmp_path.glob(f"{run_id}-*.rrd")
        from swarm.review.report import read_recording, summary_from

        summary = summary_from(read_recording(recording))
        assert (summary["iterations"], summary["delivered"], summary["agents_peak"]) == (2367, 6000, 3)
        print(f"docker stack deploy {' '.join(compose_files)} on two nodes, to the summary: {took:.1f} s")
        return logs
    finally:
        _stack_down(stack, nodes)


def test_stack_deploy_runs_on_two_nodes_as_compose_does(swarm_nodes, tmp_path):
    logs = _stack_run(swarm_nodes, tmp_path, ("stack.yaml",))
    print(logs["router"][-2000:])  # how the routers found each other (pytest shows it when asked: -s, -rA)
    # the later router found the earlier one by name, or (the name slow to list it) one bridged to the other
    assert "linked to tcp/" in logs["router"] or "bridging to tcp/" in logs["router"], logs["router"]


def test_a_secure_stack_over_tls_links_its_routers_and_gives_each_replica_its_own_identity(swarm_nodes, tmp_path):
    """stack.secure.yaml: the routers of both nodes check logins and rules and know each other by the run's
    router certificate; replica N of the agents is the pool's agentN (its task slot)."""
    from swarm.core import credentials

    creds = credentials.make(tmp_path / "creds", 3, hosts=("host.docker.internal",), pool=True)
    logs = _stack_run(swarm_nodes, tmp_path, ("stack.yaml", "stack.secure.yaml"), LINK="tls", CREDENTIALS=str(creds))
    assert "linked to tls/" in logs["router"] or "bridging to tls/" in logs["router"], logs["router"]
    assert _claimed(logs["agent"]) == ["agent1", "agent2", "agent3"], logs["agent"][-3000:]
