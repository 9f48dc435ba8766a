"""A Ray head on this machine, started as a user starts one (`ray start --head --block`) and stopped with
every process it started: the cluster of a command run with `--executor ray` and no address.

Why not `ray.init()` with no address, which starts the same processes: it starts them only when it is
called and waits for them inside the call (a second of it Ray's fixed wait before it looks again for the
raylet's registration), and `ray.shutdown()` then stops them one after another.  This head is started
when the command begins, comes up while the command sets itself up, is connected to as soon as its
raylet is registered, and ends as its whole session is killed (docs/commands.md has the seconds).

Its processes are a session of their own, so a Ctrl-C at the terminal reaches only the command, which
stops them.  The process that started it ending, even killed with SIGKILL, sends `ray start --block` a
SIGTERM (the kernel's parent-death signal, armed from a thread that lives as long as the process), on
which it stops every process it started: nothing is left running, and the next head started here
removes the folder (/tmp/swarmray*) left behind.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import queue
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import weakref
from collections.abc import Mapping
from pathlib import Path

from swarm.core.errors import RunError
from swarm.core.mesh import free_port

RAY = Path(sys.executable).with_name("ray")
STARTED = "Ray runtime started."  # what `ray start` prints once it has seen its node registered
# what the raylet logs once the GCS has registered it: usable from then on, a second before `ray start`
# says so (it looks for the node again only after a fixed second's sleep)
REGISTERED = re.compile(r"Raylet of id, \w+ started")
# Ray's settings (RayConfig values, read from RAY_<name>) for a head that serves one command, in its
# processes and in the command's own:
OWN_HEAD = {
    # a process's tries at its raylet and the raylet's at the object store it starts itself: every 50 ms,
    # 10 s in all (Ray's default, every second, brought the head up a second late one time in three)
    "RAY_raylet_client_connect_timeout_milliseconds": "50",
    "RAY_raylet_client_num_connect_attempts": "200",
    # no task events: they feed the dashboard and `ray list tasks`, which such a head has not, and sending
    # the last of them holds each process's ray.shutdown a quarter of a second
    "RAY_task_events_report_interval_ms": "0",
}
# `ray start`'s options for such a head: it has a fixed number of CPUs and nothing to scale, so it starts
# without the autoscaler's monitor (a hidden option, for clusters whose autoscaler runs elsewhere): one
# Python process fewer starting beside the command
OWN_HEAD_OPTIONS = ("--no-monitor",)
# on the parent-death signal, `ray start --block` stops its processes at once, without first waiting up
# to 30 s for the node to drain (what a cluster serving traffic needs)
AT_ONCE = {"RAY_GRACEFUL_SHUTDOWN_DRAIN_TIMEOUT_S": "0"}
PREFIX = "swarmray"
PR_SET_PDEATHSIG = 1


def processes() -> dict[int, tuple[int, str]]:
    """Every live process (zombies left out): pid -> (session, command line)."""
    found = {}
    for name in filter(str.isdigit, os.listdir("/proc")):
        with contextlib.suppress(OSError):
            fields = Path(f"/proc/{name}/stat").read_text().rpartition(")")[2].split()
            cmd = Path(f"/proc/{name}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            if fields[0] != "Z":
                found[int(name)] = (int(fields[3]), cmd)
    return found


def session_members(session: int) -> list[tuple[int, str]]:
    """The live processes of `session`: (pid, command line)."""
    return [(pid, cmd) for pid, (sid, cmd) in processes().items() if sid == session]


class RayHead:
    """`ray start --head` of `cpus` CPUs on 127.0.0.1, no dashboard, its workers importing `pythonpath`
    first, started at once in the background: a command's own (`OWN_HEAD`, `OWN_HEAD_OPTIONS`), or with
    `own=False` as a user starts one (Ray's defaults).  `address()` waits until its node is registered.
    Stopped by `stop`, or at the latest when the object is collected or this process ends."""

    def __init__(self, cpus: int, pythonpath: str, own: bool = True, env: Mapping[str, str] | None = None) -> None:
        _remove_stale_folders()
        self.port = free_port()
        self.temp = tempfile.mkdtemp(prefix=PREFIX, dir="/tmp")  # short: Ray's socket paths fit in 107 bytes
        self.log = Path(self.temp) / "head.log"
        environ = {**(OWN_HEAD if own else {}), **(env if env is not None else os.environ), **AT_ONCE}
        environ["PYTHONPATH"] = os.pathsep.join(filter(None, [pythonpath, environ.get("PYTHONPATH")]))
        cmd = [str(RAY), "start", "--head", f"--port={self.port}", f"--num-cpus={cpus}", "--node-ip-address=127.0.0.1",
               "--include-dashboard=false", "--disable-usage-stats", f"--temp-dir={self.temp}",
               *(OWN_HEAD_OPTIONS if own else ()), "--block"]  # fmt: skip
        try:
            with open(self.log, "w") as log:
                self.process = _started_for_life(cmd, env=environ, stdout=log, stderr=subprocess.STDOUT,
                                                 stdin=subprocess.DEVNULL)  # fmt: skip
        except BaseException:
            shutil.rmtree(self.temp, ignore_errors=True)
            raise
        self.session = self.process.pid  # the session it leads, which all its processes share
        (Path(self.temp) / "head.pid").write_text(str(self.session))
        self._stop = weakref.finalize(self, _kill_session, self.session, self.process, self.temp)

    def address(self, timeout: float = 120.0) -> str:
        """HOST:PORT, once the head's node is registered (so connecting waits for nothing)."""
        deadline = time.monotonic() + timeout
        while not self._registered():
            if self.process.poll() is not None:
                raise RunError(f"Ray could not start here: `ray start --head` exited ({self._said()})")
            if time.monotonic() > deadline:
                raise RunError(f"Ray did not start here in {timeout:.0f} s ({self._said()})")
            time.sleep(0.02)
        return f"127.0.0.1:{self.port}"

    def _registered(self) -> bool:
        raylet = Path(self.temp) / "session_latest" / "logs" / "raylet.out"
        with contextlib.suppress(OSError):
            if REGISTERED.search(raylet.read_text(errors="replace")):
                return True
        return STARTED in self.log.read_text(errors="replace")

    def _said(self) -> str:
        lines = [line.strip() for line in self.log.read_text(errors="replace").splitlines() if line.strip()]
        return lines[-1] if lines else "it said nothing"

    def stop(self) -> None:
        """Kill every process of the head's session, and remove its folder."""
        self._stop()

    def __enter__(self) -> RayHead:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


def _kill_session(session: int, head: subprocess.Popen, temp: str) -> None:
    """Kill every process of `session` until none is left (the raylet may start a worker meanwhile), and
    remove `temp`.  Linux hands out no pid that a live process still has as its session."""
    for _ in range(50):
        members = session_members(session)
        if not members:
            break
        for pid, _ in members:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        time.sleep(0.01)
    with contextlib.suppress(subprocess.TimeoutExpired):
        head.wait(timeout=30)
    shutil.rmtree(temp, ignore_errors=True)


def _remove_stale_folders() -> None:
    """The folders of heads whose command was killed outright (their processes stopped themselves, see
    above), so that they do not pile up in /tmp."""
    folders = list(Path("/tmp").glob(f"{PREFIX}*"))
    alive = {sid for sid, _ in processes().values()} if folders else set()  # /proc read only when needed
    for folder in folders:
        with contextlib.suppress(OSError, ValueError):
            if int((folder / "head.pid").read_text()) not in alive:
                shutil.rmtree(folder, ignore_errors=True)


def _started_for_life(cmd: list[str], **popen) -> subprocess.Popen:
    """`cmd` in a session of its own, sent SIGTERM when this process ends.  The kernel sends the
    parent-death signal when the thread that forked the child ends, so a thread that lives as long as
    this process (a daemon waiting for the child) forks it."""
    prctl = ctypes.CDLL(None, use_errno=True).prctl if sys.platform.startswith("linux") else None
    parent = os.getpid()

    def arm() -> None:  # in the child, between fork and exec: nothing that takes a lock
        signal.pthread_sigmask(signal.SIG_SETMASK, ())  # a thread's blocked signals would stay blocked
        if prctl is not None:
            prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
            if os.getppid() != parent:  # the parent ended before the signal was armed
                os._exit(1)

    handed: queue.SimpleQueue = queue.SimpleQueue()

    def keep() -> None:
        try:
            child = subprocess.Popen(cmd, start_new_session=True, preexec_fn=arm, **popen)
        except BaseException as exc:
            handed.put(exc)
            return
        handed.put(child)
        child.wait()

    threading.Thread(target=keep, name="ray-head", daemon=True).start()
    child = handed.get()
    if isinstance(child, BaseException):
        raise RunError(f"cannot start Ray here: {child}") from None
    return child
