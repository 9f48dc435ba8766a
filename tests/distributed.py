"""Helpers for multi-process tests: a world server in a thread, real agent
processes, free loopback ports, and cleanup of everything started."""

from __future__ import annotations

import contextlib
import subprocess
import sys
import threading
from pathlib import Path

from swarm.core.credentials import agent_name
from swarm.core.mesh import free_endpoint
from swarm.world_process import make_server


def start_agents(endpoint: str, run_id: str, controller: str, n: int, count: int = 1,
                 credentials: Path | None = None) -> list[subprocess.Popen]:  # fmt: skip
    """`credentials`: a secure run's folder; process i gets the identity agent<i>."""
    cmd = [sys.executable, "-m", "swarm", "agent", "--connect", endpoint, "--run-id", run_id,
           "--controller", controller, "--count", str(count)]  # fmt: skip
    own = [[] if credentials is None else ["--credentials", str(credentials / agent_name(i + 1))] for i in range(n)]
    return [subprocess.Popen(cmd + own[i], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE) for i in range(n)]


def saving_world_cmd(tmp_path, run_id: str, endpoint: str, persist_every: int) -> list[str]:
    """`swarm world` for setup1, 3 agents, seed 4, saving its state into tmp_path every `persist_every`
    ticks and writing its summary to tmp_path/summary.json: the kill -9 and restart tests' world."""
    return [sys.executable, "-m", "swarm", "world", "setup1", "--agents", "3", "--seed", "4", "--run-id", run_id,
            "--listen", endpoint, "--state-dir", str(tmp_path), "--persist-every", str(persist_every),
            "--deadline", "10", "--summary-file", str(tmp_path / "summary.json")]  # fmt: skip


def stop(procs: list[subprocess.Popen]) -> None:
    for p in procs:
        if p.poll() is None:
            p.kill()
    for p in procs:
        with contextlib.suppress(subprocess.TimeoutExpired):
            p.wait(timeout=10)


class ServerThread:
    """A world server (of the scenario's kind) running in a background thread of the test process."""

    def __init__(self, scenario, run_id: str, endpoint: str, **kw):
        self.server = make_server(scenario, run_id, listen=endpoint, **kw)
        self.summary: dict | None = None
        self.error: BaseException | None = None
        self.finished = threading.Event()
        self.closing = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        try:
            self.summary = self.server.run()
            self.server.stop_agents("finished")
        except BaseException as exc:  # reported by join()
            self.error = exc
        self.finished.set()
        if self.error is None:
            self.server.linger(self.closing.is_set)

    def start(self) -> ServerThread:
        self.thread.start()
        return self

    def join(self, timeout: float) -> dict:
        if not self.finished.wait(timeout):
            raise TimeoutError("the world did not finish in time")
        if self.error:
            raise self.error
        assert self.summary is not None
        return self.summary

    def close(self) -> None:
        self.closing.set()
        self.thread.join(10)
        self.server.close()


def run_world(scenario, run_id: str, agents: list[tuple[str, int, int]], attack=None, deadline: float = 10.0,
              told: list[str] | None = None, **kw) -> tuple[dict, object]:  # fmt: skip
    """A world in a thread and its agent processes, `agents` as (controller,
    processes, agents per process); `attack(endpoint, keys)` runs once they are
    started.  Returns the summary and the world, once every process exited 0;
    `told` gets each agent process's standard error."""
    from swarm.core import wire

    endpoint = free_endpoint()
    world = ServerThread(scenario, run_id, endpoint, deadline=deadline, **kw).start()
    procs = [p for controller, n, count in agents for p in start_agents(endpoint, run_id, controller, n, count)]
    try:
        if attack is not None:
            attack(endpoint, wire.Keys(run_id))
        summary = world.join(timeout=240)
        for p in procs:
            p.wait(timeout=30)
            err = p.stderr.read().decode()
            assert p.returncode == 0, err[-2000:]
            if told is not None:
                told.append(err)
        return summary, world.server.world
    finally:
        stop(procs)
        world.close()
