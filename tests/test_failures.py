"""A failing process of `swarm up` (or `swarm agent`) is said in one line,
exit status 2, no traceback, and nothing is left running."""

import os
import signal
import socket
import subprocess
import sys
import time

from tests.distributed import free_endpoint

SWARM = [sys.executable, "-m", "swarm"]


def _run(args, cwd, timeout=240):
    return subprocess.run([*SWARM, *args], cwd=cwd, capture_output=True, text=True, timeout=timeout)


def _one_line_error(out, *words):
    lines = [line for line in out.stderr.splitlines() if line.strip()]
    assert out.returncode == 2, out.stderr
    assert len(lines) == 1 and lines[0].startswith("swarm: error: "), out.stderr
    assert "Traceback" not in out.stderr
    for word in words:
        assert word in lines[0], lines[0]
    return lines[0]


def test_a_reused_run_id_of_another_scenario(tmp_path):
    first = _run(["up", "setup2", "--agents", "2", "--run-id", "same", "--no-record", "--json",
                  "--listen", free_endpoint()], tmp_path)  # fmt: skip
    assert first.returncode == 0, first.stderr
    again = _run(["up", "setup1", "--agents", "2", "--run-id", "same", "--no-record", "--listen", free_endpoint()],
                 tmp_path)  # fmt: skip
    _one_line_error(again, "the world failed", "another scenario", "use another --run-id")


def test_a_bad_scenario_file(tmp_path):
    (tmp_path / "bad.toml").write_text('name = "bad"\nagents = "many"\n')
    _one_line_error(_run(["up", "bad.toml", "--no-record"], tmp_path), "bad.toml")


def test_a_port_already_in_use(tmp_path):
    holder = socket.socket()
    holder.bind(("127.0.0.1", 0))
    holder.listen()
    try:
        port = holder.getsockname()[1]
        out = _run(["up", "setup2", "--agents", "2", "--no-record", "--listen", f"tcp/127.0.0.1:{port}"], tmp_path)
    finally:
        holder.close()
    _one_line_error(out, "the world failed", "cannot listen", "pick another --listen")


def test_an_agent_that_cannot_reach_the_router(tmp_path):
    out = _run(["agent", "--connect", free_endpoint(), "--run-id", "nobody", "--join-timeout", "2"], tmp_path)
    line = _one_line_error(out, "no zenoh router", "start `swarm world` first")
    assert ".rs:" not in line  # zenoh's source locations are not the user's business


def test_with_strict_an_agent_process_that_dies_stops_the_run(tmp_path):
    """A real-time run at 20 ticks/s lasts many minutes: kill one agent process mid-run.  Without
    --strict the run goes on (tests/test_up_losses.py)."""
    run = f"killed{os.getpid()}"
    up = subprocess.Popen([*SWARM, "up", "setup1", "--agents", "2", "--no-record", "--mode", "realtime", "--strict",
                           "--run-id", run, "--listen", free_endpoint()], cwd=tmp_path, stderr=subprocess.PIPE,
                          text=True, start_new_session=True)  # fmt: skip
    try:
        deadline = time.monotonic() + 180
        agents: list[int] = []
        while time.monotonic() < deadline and not agents:
            ps = subprocess.run(["pgrep", "-f", f"swarm agent .*--run-id {run}"], capture_output=True, text=True)
            agents = [int(pid) for pid in ps.stdout.split()]
            time.sleep(0.5)
        assert agents, "no agent process started"
        time.sleep(3)  # ticking
        os.kill(agents[0], signal.SIGKILL)
        _, err = up.communicate(timeout=120)
    finally:
        if up.poll() is None:
            os.killpg(up.pid, signal.SIGKILL)
    out = subprocess.CompletedProcess(up.args, up.returncode, "", err)
    _one_line_error(out, "agent process", "failed", "stopped")
    left = subprocess.run(["pgrep", "-f", f"--run-id {run}"], capture_output=True, text=True)
    assert left.stdout.strip() == "", "a process of the run is still running"
