"""Executors: the runs of an experiment, a sweep or a reproduction on worker processes here or on Ray
actors, with the same rows; a failed run retried once, then reported in one line.  Ray is tested on
a real local cluster that the tests start as a user would (`ray start --head`), and every process of
it is gone when they end."""

from __future__ import annotations

import csv
import os
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from swarm.cli import main
from swarm.core.mesh import free_port as _free_port
from swarm.experiments.executors import LocalExecutor, RayExecutor, use
from swarm.experiments.ray_head import RayHead, session_members
from swarm.experiments.runner import JobFailed, batch_run

ROOT = Path(__file__).resolve().parents[1]
SWEEP = """scenarios = ["zmaze"]
controller = "wander"
seeds = [1, 2]
max_ticks = 40
metrics = ["reached", "distance"]
[grid]
"wander.speed" = [0.4, 0.8]
"""
WALL_CLOCK = {"wall_s", "wall_seconds"}  # columns of seconds taken, which no two runs share


def _none_left(session: int, seconds: float = 30) -> None:
    """Wait until no process of `session` runs; fail naming those still running."""
    deadline = time.monotonic() + seconds
    while (left := session_members(session)) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not left, f"processes outlived the test: {left}"


@pytest.fixture(scope="module")
def cluster():
    """A Ray cluster of 2 CPUs on this machine, its workers importing this checkout: its address.
    At the end every process of it (its own session) is killed, and none is left running."""
    with RayHead(2, str(ROOT), own=False) as head:  # Ray's defaults, as a user starts one
        yield head.address()
    _none_left(head.session)


@pytest.fixture(autouse=True)
def _ray_settings_restored():
    """Ray's settings that connecting writes into this process's environment are undone after each test."""
    before = {k: os.environ.get(k) for k in ("RAY_AUTH_MODE", "RAY_USAGE_STATS_ENABLED")}
    yield
    for key, value in before.items():
        if value is None:
            os.environ.pop(key, None)
        else:
            os.environ[key] = value


@pytest.fixture(params=["here", "processes", "ray"])
def executor(request):
    """(executor, jobs): this process; two spawned processes; two Ray actors on the cluster."""
    if request.param == "ray":
        with use(RayExecutor(request.getfixturevalue("cluster"))) as ray:
            yield ray, 2
    else:
        yield LocalExecutor(), 1 if request.param == "here" else 2


def _command(script: str) -> subprocess.Popen:
    """`script` run by Python from this checkout as a command of its own (a session of its own), its
    output read as text."""
    return subprocess.Popen([sys.executable, "-c", script], cwd=ROOT, stdout=subprocess.PIPE, text=True,
                            start_new_session=True)  # fmt: skip


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return [{k: v for k, v in row.items() if k not in WALL_CLOCK} for row in csv.DictReader(f)]


# ---------------------------------------------------------------------------------- the tests' jobs


def _square(job: int) -> dict:
    return {"job": job, "square": job * job, "pid": os.getpid()}


def _fails_once(job: tuple[str, int]) -> dict:
    """Job 1 raises on its first try (a marker file remembers it was tried), then gives its row."""
    folder, k = job
    if k == 1 and not (marker := Path(folder) / "tried").exists():
        marker.touch()
        raise ValueError("first try of job 1")
    return {"job": k}


def _dies_once(job: tuple[str, int]) -> dict:
    """Job 1 kills its worker on its first try."""
    folder, k = job
    if k == 1 and not (marker := Path(folder) / "died").exists():
        marker.touch()
        os._exit(3)
    return {"job": k}


def _always_fails(job: int) -> dict:
    if job == 2:
        raise ValueError("job 2 is bad")
    return {"job": job}


def _sleepy(job: int) -> dict:
    time.sleep(30)
    return {"job": job}


# -------------------------------------------------------------------------------------------- tests


def test_a_job_that_fails_once_is_retried_and_said(executor, tmp_path, capsys):
    on, jobs = executor
    rows = batch_run(_fails_once, [(str(tmp_path), k) for k in range(4)], jobs=jobs, progress=False, executor=on)
    assert [r["job"] for r in rows] == [0, 1, 2, 3]
    err = capsys.readouterr().err
    assert "run 2 of 4" in err and "ValueError: first try of job 1" in err and "running it once more" in err


def test_a_job_that_fails_twice_stops_the_batch_naming_the_job_and_its_error(executor):
    on, jobs = executor
    with pytest.raises(JobFailed, match=r"^run 3 of 4 \(2\) failed twice: ValueError: job 2 is bad \(at .*\.py:\d+\)$"):
        batch_run(_always_fails, [0, 1, 2, 3], jobs=jobs, progress=False, executor=on)


@pytest.mark.parametrize("executor", ["processes", "ray"], indirect=True)
def test_a_worker_that_dies_is_replaced_and_its_job_retried(executor, tmp_path, capsys):
    on, jobs = executor
    rows = batch_run(_dies_once, [(str(tmp_path), k) for k in range(5)], jobs=jobs, progress=False, executor=on)
    assert [r["job"] for r in rows] == [0, 1, 2, 3, 4]
    assert "run 2 of 5" in (err := capsys.readouterr().err) and "died" in err


def test_a_sweep_through_ray_equals_the_local_pool(cluster, tmp_path):
    (tmp_path / "s.toml").write_text(SWEEP)
    for name, how in {"local": [], "ray": ["--executor", "ray", "--address", cluster]}.items():
        assert main(["sweep", str(tmp_path / "s.toml"), "--jobs", "2", "--out", str(tmp_path / name), *how]) == 0
    for file in ("runs.csv", "summary.csv"):
        assert _rows(tmp_path / "ray" / file) == _rows(tmp_path / "local" / file)
    assert len(_rows(tmp_path / "ray" / "runs.csv")) == 4


def test_an_experiment_through_ray_equals_the_local_pool(cluster, tmp_path):
    for name, how in {"local": [], "ray": ["--executor", "ray", "--address", cluster]}.items():
        argv = ["experiment", "table1", "--reps", "1", "--jobs", "2", "--out", str(tmp_path / name), *how]
        assert main(argv) == 0
    for file in ("runs.csv", "summary.csv"):
        assert _rows(tmp_path / "ray" / file) == _rows(tmp_path / "local" / file)


def test_ray_started_here_takes_only_the_cores_asked_and_leaves_nothing_running():
    """Closing the executor stops its head: the script looks, while it still runs, for its head's
    processes and folder (its own end would take them with it anyway)."""
    script = (
        "import os\n"
        "from swarm.experiments.executors import RayExecutor, use\n"
        "from swarm.experiments.ray_head import session_members\n"
        "from swarm.experiments.runner import batch_run\n"
        "from tests.test_executors import _square\n"
        "with use(RayExecutor(cpus=1)) as ray:\n"
        "    head = ray.head\n"
        "    rows = batch_run(_square, [1, 2, 3], progress=False)\n"
        "    print(ray.width(None, 10), ray.width(4, 10), [r['square'] for r in rows], {r['pid'] for r in rows})\n"
        "left = session_members(head.session)\n"
        "print(left, os.path.exists(head.temp))\n"
    )
    python = _command(script)
    out, _ = python.communicate(timeout=120)
    said, after = out.splitlines()
    assert said.startswith("1 1 [1, 4, 9] {") and str(python.pid) not in said.split("{")[1]
    assert after == "[] False"
    _none_left(python.pid)


def test_ray_started_here_ends_with_a_command_killed_outright():
    """SIGKILL gives the command no time to stop its Ray: every process of Ray's session goes with it,
    and the next head started here removes the folder it left."""
    script = (
        "import time\n"
        "from swarm.experiments.executors import RayExecutor, use\n"
        "with use(RayExecutor(cpus=1)) as ray:\n"
        "    ray.connected()\n"
        "    print(ray.head.session, ray.head.temp, flush=True)\n"
        "    time.sleep(120)\n"
    )
    python = _command(script)
    try:
        assert select.select([python.stdout], [], [], 120)[0], "the command did not connect to its Ray in 120 s"
        session, temp = python.stdout.readline().split()
        running = [cmd for _, cmd in session_members(int(session))]
        assert [cmd for cmd in running if "raylet" in cmd], "no raylet ran"
        # a head of the command's own has nothing to scale: no autoscaler monitor (started before the raylet)
        assert not [cmd for cmd in running if "autoscaler/_private/monitor.py" in cmd], running
    finally:
        python.kill()
        python.wait(timeout=10)
    _none_left(int(session))
    assert Path(temp).exists()
    RayHead(1, str(ROOT)).stop()
    assert not Path(temp).exists()


@pytest.mark.parametrize("command", [["sweep", "s.toml"], ["experiment", "table1"], ["reproduce", "simonin2007"]])
def test_an_unreachable_cluster_is_one_line_saying_what_to_do(command, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text(SWEEP)
    port = _free_port()
    argv = [*command, "--out", str(tmp_path / "out")]
    assert main([*argv, "--executor", "ray", "--address", f"127.0.0.1:{port}"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"swarm: error: no Ray cluster answers at 127.0.0.1:{port}") and err.count("\n") == 1
    assert f"ray start --head --port={port}" in err
    assert main([*argv, "--address", f"127.0.0.1:{port}"]) == 2  # an address is for Ray only
    assert "add --executor ray" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_ctrl_c_ends_the_worker_processes():
    script = (
        "from swarm.experiments.runner import batch_run\n"
        "from tests.test_executors import _sleepy\n"
        "batch_run(_sleepy, list(range(4)), jobs=2, progress=False)\n"
    )
    # SIGINT as a terminal's: a shell starts background jobs (a suite run with `&`) with it ignored, the
    # ignoring is inherited, and Python then never raises KeyboardInterrupt
    python = subprocess.Popen([sys.executable, "-c", script], cwd=ROOT, stderr=subprocess.PIPE, text=True,
                              start_new_session=True,
                              preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))  # fmt: skip
    deadline = time.monotonic() + 60
    while len([p for p, cmd in session_members(python.pid) if "spawn_main" in cmd]) < 2:
        assert time.monotonic() < deadline and python.poll() is None, "the two workers did not start"
        time.sleep(0.2)
    os.kill(python.pid, signal.SIGINT)
    assert "KeyboardInterrupt" in python.communicate(timeout=60)[1]
    _none_left(python.pid, seconds=10)
