"""`swarm up` survives an agent process that dies: kill -9 of a real agent
process during a real run.  By default one line names it, the world counts
its agents lost and the run finishes (exit status 0); `--respawn` starts a
replacement whose agent drives the lost robot on; `--strict` stops the run
(tests/test_failures.py).  The rules of `swarm.launcher._Losses` (what is
replaced, how often, when no agent is left) are tested on stand-in agent
processes, which die as often as a test needs in a fraction of a second."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import threading
import time

import pytest

from swarm.core import wire
from swarm.core.bus import open_client, open_router
from swarm.core.errors import RunError
from swarm.launcher import _Children, _Losses
from tests.distributed import free_endpoint

SWARM = [sys.executable, "-m", "swarm"]


class _Up:
    """`swarm up ... --json` in the background: its standard error read line by line as it comes,
    the world's info and the agent processes at hand."""

    def __init__(self, args: list[str], run_id: str, cwd):
        self.run_id, self.endpoint = run_id, free_endpoint()
        self.proc = subprocess.Popen([*SWARM, "up", *args, "--no-record", "--json", "--run-id", run_id, "--listen",
                                      self.endpoint], cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     text=True, start_new_session=True)  # fmt: skip
        self.lines: list[str] = []
        self.out = ""
        self._readers = [threading.Thread(target=self._read_err, daemon=True),
                         threading.Thread(target=self._read_out, daemon=True)]  # fmt: skip
        for t in self._readers:
            t.start()
        self.session = None

    def _read_err(self) -> None:
        for line in self.proc.stderr:
            self.lines.append(line.rstrip("\n"))

    def _read_out(self) -> None:
        self.out = self.proc.stdout.read()

    def info(self) -> dict | None:
        if self.session is None:
            try:
                self.session = open_client(self.endpoint, timeout=1.0)
            except ConnectionError:
                return None
        return wire.world_info(self.session, wire.Keys(self.run_id), timeout=1.0)

    def wait_for(self, what, timeout: float = 120.0):
        """Until `what()` is true (returned), or fail with what `swarm up` said."""
        deadline = time.monotonic() + timeout
        while not (found := what()):
            assert self.proc.poll() is None, "\n".join(self.lines)
            assert time.monotonic() < deadline, "\n".join(self.lines)
            time.sleep(0.1)
        return found

    def ticking(self, tick: int) -> dict:
        return self.wait_for(lambda: (info := self.info()) is not None and info["tick"] >= tick and info)

    def agent_pids(self) -> list[int]:
        ps = subprocess.run(["pgrep", "-f", f"swarm agent .*--run-id {self.run_id}"], capture_output=True, text=True)
        return sorted(int(pid) for pid in ps.stdout.split())

    def finish(self, timeout: float = 120.0) -> tuple[int, dict]:
        self.proc.wait(timeout=timeout)
        for t in self._readers:
            t.join(10)
        return self.proc.returncode, json.loads(self.out) if self.out.strip() else {}

    def close(self) -> None:
        if self.session is not None:
            self.session.close()
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()


def _nothing_left(run_id: str) -> bool:
    left = subprocess.run(["pgrep", "-f", f"--run-id {run_id}"], capture_output=True, text=True)
    return left.stdout.strip() == ""


def test_an_agent_process_killed_mid_run_is_a_loss_and_the_run_finishes(tmp_path):
    """setup2 with 4 agents in real time at 100 ticks/s: some 4 s of foraging, kill -9 one agent
    process a few ticks in; the three others finish it."""
    run = f"loss{os.getpid()}"
    up = _Up(["setup2", "--agents", "4", "--seed", "9", "--mode", "realtime", "--rate", "100"], run, tmp_path)
    try:
        up.ticking(10)
        pids = up.agent_pids()
        assert len(pids) == 4
        os.kill(pids[0], signal.SIGKILL)
        status, summary = up.finish()
        assert status == 0, "\n".join(up.lines)
    finally:
        up.close()
    said = [line for line in up.lines if "died" in line]
    assert len(said) == 1, up.lines
    assert re.fullmatch(r"swarm: agent process \d \(agent \d\) died: it exited with status -9 and said nothing; "
                        r"the run goes on without its agents", said[0]), said[0]  # fmt: skip
    assert "Traceback" not in "\n".join(up.lines)
    assert summary["finished"] and summary["delivered"] == summary["total"]
    assert summary["agents_lost"] == 1 and summary["joins"] == 4
    assert summary["agent_processes_died"] == 1 and "agent_processes_replaced" not in summary
    assert _nothing_left(run), "a process of the run is still running"


def test_respawn_replaces_a_killed_agent_process_whose_robot_drives_on(tmp_path):
    """zmaze's carrot robots in real time at 40 ticks/s (the first is at its goal at tick ~80, the
    second at ~190): kill -9 one agent process a few ticks in; its robot holds still until the
    replacement's agent takes it over and drives it to its goal."""
    run = f"respawn{os.getpid()}"
    up = _Up(["zmaze", "--agents", "2", "--mode", "realtime", "--rate", "40", "--respawn"], run, tmp_path)
    try:
        up.ticking(5)
        pids = up.agent_pids()
        assert len(pids) == 2
        os.kill(pids[0], signal.SIGKILL)
        died = up.wait_for(lambda: next((m for line in up.lines
                                         if (m := re.search(r"\(agent (\d)\) died: .*a replacement follows", line))),
                                        None))  # fmt: skip
        robot = int(died[1])
        held = next(r for r in up.info()["robots"] if r["agent"] == robot)
        status, summary = up.finish()
        assert status == 0, "\n".join(up.lines)
    finally:
        up.close()
    assert not held["reached"]  # lost on its way
    assert any(re.fullmatch(rf"swarm: agent process 3 started in place of agent process \d for agent {robot} "
                            r"\(replacement 1 of at most 3\)", line) for line in up.lines), up.lines  # fmt: skip
    assert summary["finished"] and summary["reached"] == 2  # both at their goals: the lost one driven on
    assert summary["agents_lost"] == 1 and summary["joins"] == 3
    assert summary["agent_processes_died"] == 1 and summary["agent_processes_replaced"] == 1
    after = next(r for r in summary["robots"] if r["agent"] == robot)
    assert after["reached"] and after["path_length"] > held["path_length"] + 0.05
    assert _nothing_left(run), "a process of the run is still running"


# ------------------------------------- the rules, on stand-in agent processes

# A stand-in agent process: it says its agents' ids (its argument) where `swarm agent --ids-file` would,
# as a joined agent process does, then waits to be killed.
STAND_IN = ("import os, sys, time; open(sys.argv[-1] + '.part', 'w').write(sys.argv[1]); "
            "os.replace(sys.argv[-1] + '.part', sys.argv[-1]); time.sleep(120)")  # fmt: skip


@pytest.fixture
def rules(tmp_path):
    """`_Losses` over real `_Children` (stand-in agent processes, started as `swarm up` starts its
    own) and a real zenoh session on which no world answers: replacements start after `let_go` (0)."""
    session = open_router(free_endpoint())
    made = []

    def make(on_loss: str, n: int = 2, max_respawns: int = 3) -> tuple[_Losses, _Children, list[str]]:
        children = _Children(tmp_path / f"run{len(made)}", "rules")
        children.folder.mkdir()
        children.start("the world", [sys.executable, "-c", "import time; time.sleep(120)"])
        for i in range(n):
            children.start(f"agent process {i + 1}", [sys.executable, "-c", STAND_IN, f"[{i}]"], agent=True)
        losses = _Losses(on_loss, max_respawns, let_go=0.0)
        losses.follow(children, session, wire.Keys("rules"))
        losses.ticking = True
        made.append(children)
        return losses, children, []

    yield make
    for children in made:
        for p in children.procs:
            p.kill()
            p.wait()
    session.close()


def _kill(p: subprocess.Popen, joined: bool = True) -> None:
    """kill -9; `joined`: once it has said its agents' ids."""
    deadline = time.monotonic() + 30
    while joined and not os.path.exists(p.args[-1]):  # args: the command, then --ids-file FILE
        assert time.monotonic() < deadline, "the stand-in never said its ids"
        time.sleep(0.01)
    p.kill()
    p.wait()


def test_a_death_before_the_run_ticks_or_with_strict_stops_the_run(rules):
    for on_loss, ticking in (("go-on", False), ("respawn", False), ("strict", True)):
        losses, children, said = rules(on_loss)
        losses.ticking = ticking
        _kill(children.procs[1])
        with pytest.raises(RunError, match="agent process 1 failed: it exited with status -9 and said nothing"):
            losses.check(said.append)


def test_respawn_stops_after_max_respawns_and_when_a_replacement_never_joined(rules):
    losses, children, said = rules("respawn", max_respawns=2)
    _kill(children.procs[1])
    losses.check(said.append)
    assert said == ["swarm: agent process 1 (agent 0) died: it exited with status -9 and said nothing; a replacement "
                    "follows", "swarm: agent process 3 started in place of agent process 1 for agent 0 (replacement "
                    "1 of at most 2)"]  # fmt: skip
    _kill(children.procs[-1])
    losses.check(said.append)
    assert said[-1].endswith("(replacement 2 of at most 2)")
    _kill(children.procs[-1])
    losses.check(said.append)
    assert said[-1].endswith("not replaced: its agents were given a new process 2 times already (--max-respawns 2)")
    _kill(children.procs[2])  # the other one: replaced, and its replacement dies before it says its ids
    losses.check(said.append)
    _kill(children.procs[-1], joined=False)
    with pytest.raises(RunError) as stopped:
        losses.check(said.append)
    assert str(stopped.value) == (
        "agent process 5 (for agent 1, not joined yet) died: it exited with status -9 and said nothing; not "
        "replaced, as it died before its agents joined; with no agent process left the world cannot go on; every "
        "process of the run was stopped"
    )
    assert losses.summary() == {"agent_processes_died": 5, "agent_processes_replaced": 3}


def test_without_respawn_the_run_goes_on_until_no_agent_is_left(rules):
    losses, children, said = rules("go-on")
    _kill(children.procs[2])
    losses.check(said.append)
    assert said == ["swarm: agent process 2 (agent 1) died: it exited with status -9 and said nothing; "
                    "the run goes on without its agents"]  # fmt: skip
    assert len(children.procs) == 3  # nothing started
    losses, children, said = rules("go-on")
    _kill(children.procs[1])
    _kill(children.procs[2])
    with pytest.raises(RunError) as stopped:
        losses.check(said.append)
    assert said == ["swarm: agent process 1 (agent 0) died: it exited with status -9 and said nothing; "
                    "the run goes on without its agents"]  # fmt: skip
    assert str(stopped.value) == (
        "agent process 2 (agent 1) died: it exited with status -9 and said nothing; it "
        "was the last agent process (--respawn replaces them); with no agent process "
        "left the world cannot go on; every process of the run was stopped"
    )
    assert losses.summary() == {"agent_processes_died": 2}
