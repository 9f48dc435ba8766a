"""A Ray cluster on this machine, started as a user starts one (`ray start --head`) and stopped with
every process it started: the executors bench's running cluster, and the Ray tests'."""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

RAY = Path(sys.executable).with_name("ray")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def processes() -> dict[int, tuple[int, int, str]]:
    """Every live process (zombies left out): pid -> (parent, session, command line)."""
    found = {}
    for name in filter(str.isdigit, os.listdir("/proc")):
        with contextlib.suppress(OSError):
            fields = Path(f"/proc/{name}/stat").read_text().rpartition(")")[2].split()
            cmd = Path(f"/proc/{name}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            if fields[0] != "Z":
                found[int(name)] = (int(fields[1]), int(fields[3]), cmd)
    return found


@contextlib.contextmanager
def ray_head(cpus: int, pythonpath: str) -> Iterator[tuple[str, int]]:
    """A head of `cpus` CPUs, no dashboard, whose workers import `pythonpath` first: (its address,
    its session).  Its processes form a session of their own, all killed when the block ends."""
    port = free_port()
    temp = tempfile.mkdtemp(prefix="ray", dir="/tmp")  # short: Ray's socket paths must fit in 107 bytes
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [pythonpath, os.environ.get("PYTHONPATH")])))
    cmd = [str(RAY), "start", "--head", f"--port={port}", f"--num-cpus={cpus}", "--include-dashboard=false",
           "--disable-usage-stats", f"--temp-dir={temp}", "--block"]  # fmt: skip
    with open(Path(temp) / "head.log", "w") as log:
        head = subprocess.Popen(cmd, env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        deadline = time.monotonic() + 60
        while True:
            if head.poll() is not None:
                raise RuntimeError(f"ray start --head exited: {(Path(temp) / 'head.log').read_text()[-2000:]}")
            with contextlib.suppress(OSError), socket.create_connection(("127.0.0.1", port), timeout=1):
                break
            if time.monotonic() > deadline:
                raise RuntimeError("the Ray head did not open its port in 60 s")
            time.sleep(0.2)
        yield f"127.0.0.1:{port}", head.pid
    finally:
        for pid in [p for p, (_, sid, _) in processes().items() if sid == head.pid]:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        head.wait(timeout=30)
        shutil.rmtree(temp, ignore_errors=True)
