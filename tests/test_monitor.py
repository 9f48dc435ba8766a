"""The pieces a deployment is made of, as real processes on 127.0.0.1: a bare
router (`swarm router`), a world that starts with 2 agents and takes a third
later (`--start-with`), the monitor that prints the summary when the run ends,
`swarm status` before and after, and a late agent turned away once it has ended."""

from __future__ import annotations

import json
import subprocess
import sys
import time
import uuid

import pytest

from tests.distributed import free_endpoint, start_agents, stop

pytestmark = pytest.mark.timeout(300)
SWARM = [sys.executable, "-m", "swarm"]


def _status(endpoint: str, run_id: str, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run([*SWARM, "status", "--connect", endpoint, "--run-id", run_id, "--timeout", "2", *extra],
                          capture_output=True, text=True, timeout=60)  # fmt: skip


def test_status_says_when_nobody_answers():
    endpoint = free_endpoint()
    out = _status(endpoint, "nobody", "--router")
    assert out.returncode == 1 and f"no router at {endpoint} answered" in out.stderr
    out = _status(endpoint, "nobody")
    assert out.returncode == 1 and "no world of run 'nobody'" in out.stderr and "Traceback" not in out.stderr


def test_router_world_monitor_and_a_late_agent(tmp_path):
    endpoint, run_id = free_endpoint(), f"mon{uuid.uuid4().hex[:6]}"
    procs = [subprocess.Popen([*SWARM, "router", "--listen", endpoint], stderr=subprocess.PIPE)]
    try:
        deadline = time.monotonic() + 30
        while _status(endpoint, run_id, "--router").returncode != 0:
            assert time.monotonic() < deadline, "the router did not come up"
        world = subprocess.Popen(
            # setup1: with 2 agents ~29,000 ticks (tens of seconds), long enough for the late agent to join on
            # any machine (`open` ends in ~3 s, close to the time one `swarm status` takes to start)
            [*SWARM, "world", "setup1", "--agents", "3", "--start-with", "2", "--seed", "1", "--connect", endpoint,
             "--run-id", run_id, "--record", f"{tmp_path}/", "--linger", "60", "--state-dir", str(tmp_path)],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
        procs.append(world)
        monitor = subprocess.Popen([*SWARM, "monitor", "--connect", endpoint, "--run-id", run_id, "--log-every", "0.5"],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
        procs.append(monitor)
        procs += start_agents(endpoint, run_id, "cmarking", 2)
        deadline = time.monotonic() + 120
        while True:  # ticking with the first two
            out = _status(endpoint, run_id, "--json")
            if out.returncode == 0 and (info := json.loads(out.stdout))["tick"] > 20:
                break
            assert time.monotonic() < deadline, "the world did not start with 2 agents"
        assert info["agents_alive"] == 2 and not info["ended"]
        procs += start_agents(endpoint, run_id, "cmarking", 1)  # a third one joins the running world

        out, err = monitor.communicate(timeout=180)
        assert monitor.returncode == 0, err
        assert "setup1: cmarking x3, seed 1: finished after" in out
        assert "agents joined 3 (at most 3 at once), lost 0" in out, out
        assert "waiting for agents" in err or "tick " in err  # progress went to the log

        ended = _status(endpoint, run_id)
        assert ended.returncode == 0 and f"run {run_id}: ended at tick" in ended.stdout
        late = subprocess.run([*SWARM, "agent", "--connect", endpoint, "--run-id", run_id],
                              capture_output=True, text=True, timeout=60)  # fmt: skip
        assert late.returncode == 0 and "the run has ended" in late.stderr, late.stderr
        assert len(list(tmp_path.glob(f"{run_id}-*.rrd"))) == 1  # --record FOLDER/: one new file per run
    finally:
        stop(procs)
