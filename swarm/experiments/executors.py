"""Where `batch_run`'s jobs run (swarm/experiments/runner.py): worker processes on this machine, or
Ray actors on a Ray cluster.

An executor starts workers.  Each warms up once (compiles or loads the kernels), then runs the chunks
of jobs it is handed, holding two at most: the one it runs and the next, so it never waits for work.
A job that raises comes back as a `Failure` (its error in one line and where it was raised); a worker
that dies fails the chunk it was running and hands back, untried, the one it held.  batch_run hands
out the jobs, keeps the rows in the jobs' order and retries a failed job once.

- `LocalExecutor`: spawned processes on this machine; one worker is this process itself.
- `RayExecutor`: actors of one CPU each on the Ray cluster at `address`, or on a Ray head started
  here for the command (swarm/experiments/ray_head.py: no dashboard, at most `cpus` CPUs).

A command chooses one executor for all its runs (`--executor local|ray [--address ADDR]`, see
`add_executor_options`) and sets it with `use`; batch_run asks `current()`.  In Python:

    with use(RayExecutor("10.0.0.1:6379")):
        sweep("my-sweep.toml")
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing as mp
import os
import re
import signal
import socket
import sys
import traceback
from collections import deque
from collections.abc import Callable, Iterator
from contextvars import ContextVar
from dataclasses import dataclass, field
from multiprocessing.connection import wait
from pathlib import Path
from typing import Any, Protocol

from swarm.core.errors import RunError, one_line
from swarm.experiments.ray_head import OWN_HEAD, RayHead

IN_HAND = 2  # chunks a worker holds at once: the one it runs and the next
EXECUTORS = ("local", "ray")
INSTALL_HINT = "every host of the cluster needs this swarm importable (the same checkout or wheel, installed there)"

Chunk = list[tuple[int, Any]]  # (the job's number, the job)
Outcome = tuple[int, "dict | Failure | None"]  # a row, why there is none, or None: handed back untried


@dataclass(frozen=True)
class Failure:
    """Why a job gave no row: its error in one line and where it was raised, or how its worker died."""

    error: str
    where: str = ""

    @classmethod
    def of(cls, exc: BaseException) -> Failure:
        frames = traceback.extract_tb(exc.__traceback__)
        return cls(one_line(exc), f"{frames[-1].filename}:{frames[-1].lineno}" if frames else "")

    def __str__(self) -> str:
        return f"{self.error} (at {self.where})" if self.where else self.error


class WorkerFailed(RunError):
    """A worker could not start: its warm-up raised, or (Ray) it could not import the job's code."""


def run_chunk(fn: Callable[[Any], dict], chunk: Chunk) -> list[Outcome]:
    """What every worker does with a chunk: each job's row, or its Failure."""
    outcomes: list[Outcome] = []
    for i, job in chunk:
        try:
            outcomes.append((i, fn(job)))
        except Exception as exc:
            outcomes.append((i, Failure.of(exc)))
    return outcomes


def processes_for(jobs: int | None, work: int) -> int:
    """Worker processes: `jobs` (default every core), never more than there is work."""
    return max(1, min(jobs or os.cpu_count() or 1, work))


class Workers(Protocol):
    """Started workers, as batch_run drives them."""

    def free(self) -> int:
        """How many chunks the workers can take now (workers still to start included)."""

    def submit(self, chunk: Chunk) -> None:
        """Hand `chunk` to the worker holding the fewest, starting one while there are fewer than asked."""

    def results(self) -> list[Outcome]:
        """Wait for a chunk to come back, or for a worker to die; what that ends."""

    def close(self) -> None:
        """End every worker, whatever it is doing."""


class Executor(Protocol):
    name: str

    def width(self, jobs: int | None, work: int) -> int:
        """Workers for `work` jobs when `jobs` are asked (None: as many as there are CPUs)."""

    def start(self, fn: Callable[[Any], dict], width: int, warm_up: Callable[..., None] | None,
              warm_args: tuple) -> Workers:  # fmt: skip
        """`width` workers (started as chunks come) that warm up once and run `fn` on each job."""

    def close(self) -> None:
        """Let go of what the executor holds (a Ray connection); the command is done with it."""


# ---------------------------------------------------------------------------------------------- local


class LocalExecutor:
    """Spawned worker processes on this machine (each given this process's import path); one worker
    is this process itself, warmed up already by batch_run."""

    name = "local"

    def width(self, jobs: int | None, work: int) -> int:
        return processes_for(jobs, work)

    def start(self, fn, width, warm_up, warm_args) -> Workers:  # type: ignore[no-untyped-def]
        return _Here(fn) if width == 1 else _Processes(fn, width, warm_up, warm_args)

    def close(self) -> None:
        pass


class _Here:
    """The one worker is this process: a chunk runs when its results are asked for."""

    def __init__(self, fn: Callable[[Any], dict]) -> None:
        self.fn = fn
        self.held: deque[Chunk] = deque()

    def free(self) -> int:
        return 0 if self.held else 1

    def submit(self, chunk: Chunk) -> None:
        self.held.append(chunk)

    def results(self) -> list[Outcome]:
        return run_chunk(self.fn, self.held.popleft())

    def close(self) -> None:
        self.held.clear()


def _serve(conn, fn: Callable[[Any], dict], warm_up: Callable[..., None] | None, warm_args: tuple) -> None:
    """A worker process: warm up (a Failure sent back if that raises), then run chunks until told to stop."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the command's, which ends its workers
    try:
        if warm_up is not None:
            warm_up(*warm_args)
    except Exception as exc:
        conn.send(Failure.of(exc))
        return
    with contextlib.suppress(EOFError, OSError):  # the command went away
        while (chunk := conn.recv()) is not None:
            conn.send(run_chunk(fn, chunk))


@dataclass(eq=False)
class _Worker:
    """A started worker (a process and its pipe, or a Ray actor) and the chunks it holds, oldest first,
    each with what brings its result back (a Ray ObjectRef; nothing for a pipe)."""

    handle: Any
    held: deque[tuple[Chunk, Any]] = field(default_factory=deque)


class _Started:
    """Workers started as chunks come, up to `width`; each holds at most IN_HAND chunks."""

    def __init__(self, width: int) -> None:
        self.width = width
        self.workers: list[_Worker] = []

    def _start(self) -> Any:
        raise NotImplementedError

    def free(self) -> int:
        return sum(IN_HAND - len(w.held) for w in self.workers) + IN_HAND * (self.width - len(self.workers))

    def _next(self) -> _Worker:
        """The worker to hand the next chunk: a new one while there are fewer than `width`, else the least held."""
        if len(self.workers) < self.width:
            self.workers.append(_Worker(self._start()))
        return min(self.workers, key=lambda w: len(w.held))

    def _died(self, worker: _Worker, failure: Failure) -> list[Outcome]:
        """A dead worker's chunks: the one it was running failed, the others come back untried."""
        self.workers.remove(worker)
        first, *others = [chunk for chunk, _ in worker.held] or [[]]
        return [(i, failure) for i, _ in first] + [(i, None) for chunk in others for i, _ in chunk]


class _Processes(_Started):
    def __init__(self, fn, width: int, warm_up, warm_args: tuple) -> None:  # type: ignore[no-untyped-def]
        super().__init__(width)
        self.args = (fn, warm_up, warm_args)

    def _start(self) -> tuple[Any, Any]:
        context = mp.get_context("spawn")
        conn, theirs = context.Pipe()
        process = context.Process(target=_serve, args=(theirs, *self.args), daemon=True, name="swarm-worker")
        process.start()
        theirs.close()
        return process, conn

    def submit(self, chunk: Chunk) -> None:
        worker = self._next()
        worker.held.append((chunk, None))
        with contextlib.suppress(OSError):  # it died: results() finds out from its exit
            worker.handle[1].send(chunk)

    def results(self) -> list[Outcome]:
        whose = {end: w for w in self.workers for end in (w.handle[1], w.handle[0].sentinel)}
        outcomes: list[Outcome] = []
        for worker in dict.fromkeys(whose[ready] for ready in wait(list(whose))):
            process, conn = worker.handle
            try:
                message = conn.recv() if conn.poll() else None
            except (EOFError, OSError):
                message = None
            if isinstance(message, Failure):
                raise WorkerFailed(f"a worker process could not start: its warm-up raised {message}")
            if message is not None:
                worker.held.popleft()  # a pipe keeps the order
                outcomes += message
            elif not process.is_alive():
                process.join()
                conn.close()
                outcomes += self._died(worker, Failure(f"its worker process died ({_exit(process.exitcode)})"))
        return outcomes

    def close(self) -> None:
        for worker in self.workers:
            worker.handle[0].terminate()
        for worker in self.workers:
            worker.handle[0].join()
            worker.handle[1].close()
        self.workers.clear()


def _exit(code: int | None) -> str:
    return f"killed by {signal.Signals(-code).name}" if code is not None and code < 0 else f"exit status {code}"


# ------------------------------------------------------------------------------------------------ ray


class RayExecutor:
    """Actors of one CPU each on the Ray cluster at `address` (HOST:PORT of `ray start --head`; default
    $RAY_ADDRESS), or, with none, on a Ray head started here as the executor is made, so that it comes
    up while the command sets itself up, and stopped with it (`close`; no dashboard, `cpus` CPUs: default
    every core).  Its workers import the job's code themselves: on a cluster every host needs this swarm
    installed; here they are given this process's import path."""

    name = "ray"

    def __init__(self, address: str | None = None, cpus: int | None = None) -> None:
        self.address = address or os.environ.get("RAY_ADDRESS") or None
        self.ray: Any = None
        self.head: RayHead | None = None
        self.closed = False
        if self.address is not None:
            _check_reachable(self.address)
        else:
            _use_tokens_as_ray_does()
            self.head = RayHead(cpus or os.cpu_count() or 1, _import_path())

    def connected(self) -> Any:
        """The ray module, connected on first use (to the head started here once its node is registered)."""
        if self.closed:
            raise RunError("this Ray executor is closed: make another")
        if self.ray is None:
            if self.head is None:
                self.ray = _connect(self.address, mine=False)  # type: ignore[arg-type]
            else:
                import ray  # (a fifth of a second, taken while the head finishes starting)

                try:
                    with _environ(OWN_HEAD):  # this process's settings as its head's, read as it connects
                        self.ray = _connect(self.head.address(), mine=True)
                except BaseException:  # a half-made connection must not outlive the head it was to
                    with contextlib.suppress(Exception):
                        ray.shutdown()
                    raise
        return self.ray

    def width(self, jobs: int | None, work: int) -> int:
        cpus = int(self.connected().cluster_resources().get("CPU", 0))
        if cpus < 1:
            raise RunError(f"the Ray cluster at {self.address} has no CPU for a worker")
        return max(1, min(jobs or cpus, cpus, work))

    def start(self, fn, width, warm_up, warm_args) -> Workers:  # type: ignore[no-untyped-def]
        return _Actors(self.connected(), width, (fn, warm_up, warm_args))

    def close(self) -> None:
        self.closed = True
        if self.ray is not None:
            self.ray.shutdown()  # a driver's leaving: the cluster goes on
            self.ray = None
        if self.head is not None:
            self.head.stop()
            self.head = None


class RayWorker:
    """A Ray actor's body: warms up once (a failure kept, and given back for every chunk), then runs chunks."""

    def __init__(self, fn: Callable[[Any], dict], warm_up: Callable[..., None] | None, warm_args: tuple) -> None:
        self.fn, self.broken = fn, None
        try:
            if warm_up is not None:
                warm_up(*warm_args)
        except Exception as exc:
            self.broken = Failure.of(exc)

    def run(self, chunk: Chunk) -> list[Outcome] | Failure:
        return self.broken or run_chunk(self.fn, chunk)


class _Actors(_Started):
    def __init__(self, ray: Any, width: int, args: tuple) -> None:
        super().__init__(width)
        self.ray, self.args = ray, args
        self.actor_class = ray.remote(num_cpus=1)(RayWorker)

    def _start(self) -> Any:
        return self.actor_class.remote(*self.args)

    def submit(self, chunk: Chunk) -> None:
        worker = self._next()
        worker.held.append((chunk, worker.handle.run.remote(chunk)))

    def results(self) -> list[Outcome]:
        whose = {ref: w for w in self.workers for _, ref in w.held}
        [ready], _ = self.ray.wait(list(whose), num_returns=1)
        worker = whose[ready]
        try:
            message = self.ray.get(ready)
        except self.ray.exceptions.RayError as exc:
            if getattr(exc, "_actor_init_failed", False):
                raise WorkerFailed(f"a Ray worker could not start: {_last_line(exc)}; {INSTALL_HINT}") from None
            with contextlib.suppress(Exception):
                self.ray.kill(worker.handle)
            return self._died(worker, Failure(f"its Ray worker died ({_last_line(exc)})"))
        if isinstance(message, Failure):
            raise WorkerFailed(f"a Ray worker could not start: its warm-up raised {message}")
        worker.held.remove(next(held for held in worker.held if held[1] == ready))  # ray.wait keeps no order
        return message

    def close(self) -> None:
        for worker in self.workers:
            with contextlib.suppress(Exception):
                self.ray.kill(worker.handle)
        self.workers.clear()


def _last_line(exc: BaseException) -> str:
    """A Ray error in a line: why its worker exited, else the last line of its text (the error raised)."""
    text = str(exc)
    if found := re.search(r"Worker exit detail: (.+?)\.(\s|$)", text):
        return found.group(1)
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    return lines[-1] if lines else type(exc).__name__


def _check_reachable(address: str) -> None:
    """Refuse, in one line saying what to do, an address where nothing answers (Ray would retry a minute)."""
    host, _, port = address.removeprefix("ray://").rpartition(":")
    if not port.isdigit():
        return  # "auto", or another form Ray reads itself
    try:
        socket.create_connection((host or "127.0.0.1", int(port)), timeout=5).close()
    except OSError as exc:
        raise RunError(f"no Ray cluster answers at {address} ({exc.strerror or exc}): start one on that host with "
                       f"`ray start --head --port={port}`, or leave out --address to start Ray on this machine"
                       ) from None  # fmt: skip


def _use_tokens_as_ray_does(address: str | None = None) -> None:
    """Ray's own rule for a cluster it starts or finds by itself, said quietly: token authentication,
    with a token made and kept in ~/.ray/auth_token for a cluster started here where there is none yet."""
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    if "RAY_AUTH_MODE" not in os.environ and (address is None or _token_here()):
        os.environ["RAY_AUTH_MODE"] = "token"
    if address is None and os.environ.get("RAY_AUTH_MODE") == "token" and not _token_here():
        from ray._private.authentication.authentication_token_setup import generate_and_save_token

        generate_and_save_token()


def _connect(address: str, mine: bool) -> Any:
    """The ray module, connected to the cluster at `address` (`mine`: the head this command started, which
    set Ray's token rule as it started it)."""
    if not mine:
        _use_tokens_as_ray_does(address)
    import ray

    before = signal.getsignal(signal.SIGTERM)
    try:
        ray.init(address=address, logging_level=logging.WARNING)
    except Exception as exc:
        causes = " ".join(str(e) for e in _chain(exc))
        if "InvalidAuthToken" in causes and not mine:
            raise RunError(f"the Ray cluster at {address} refused this machine's token: copy the head's "
                           "~/.ray/auth_token here (or set RAY_AUTH_TOKEN)") from None  # fmt: skip
        raise RunError(f"cannot use Ray {'here' if mine else f'at {address}'}: {one_line(exc)}") from None
    finally:  # Ray sets a SIGTERM handler of its own (exit at once): the command's ends it as Ctrl-C does
        with contextlib.suppress(TypeError, ValueError):  # none set from Python; not the main thread
            signal.signal(signal.SIGTERM, before)
    return ray


def _chain(exc: BaseException | None) -> Iterator[BaseException]:
    while exc is not None:
        yield exc
        exc = exc.__cause__ or exc.__context__


def _token_here() -> bool:
    return (
        bool(os.environ.get("RAY_AUTH_TOKEN") or os.environ.get("RAY_AUTH_TOKEN_PATH"))
        or (Path.home() / ".ray" / "auth_token").is_file()
    )


def _import_path() -> str:
    """This process's import path beyond its Python's own (this checkout, a user's folders), then PYTHONPATH."""
    own = (sys.prefix, sys.base_prefix)
    mine = [os.path.abspath(p) for p in sys.path if p and os.path.isdir(p) and not p.startswith(own)]
    return os.pathsep.join(dict.fromkeys([*mine, *filter(None, os.environ.get("PYTHONPATH", "").split(os.pathsep))]))


@contextlib.contextmanager
def _environ(settings: dict[str, str]) -> Iterator[None]:
    """`settings` in this process's environment for the block, where it does not set them itself."""
    added = {name: value for name, value in settings.items() if name not in os.environ}
    os.environ.update(added)
    try:
        yield
    finally:
        for name in added:
            os.environ.pop(name, None)


# -------------------------------------------------------------------------------- the command's choice

_CURRENT: ContextVar[Executor | None] = ContextVar("swarm_executor", default=None)


def current() -> Executor:
    """The executor batch_run runs on: the one `use` set, else the local one."""
    return _CURRENT.get() or LocalExecutor()


@contextlib.contextmanager
def use(executor: Executor) -> Iterator[Executor]:
    """Run every batch inside on `executor`; closed at the end."""
    token = _CURRENT.set(executor)
    try:
        yield executor
    finally:
        _CURRENT.reset(token)
        executor.close()


def add_executor_options(parser) -> None:  # type: ignore[no-untyped-def]
    parser.add_argument("--executor", choices=EXECUTORS, default="local",
                        help="where the runs run: local (worker processes on this machine, the default) or ray "
                        "(Ray actors, one per CPU: on the cluster at --address, else on Ray started here)")  # fmt: skip
    parser.add_argument("--address", metavar="HOST:PORT", help="with --executor ray: the head of a running "
                        "Ray cluster (`ray start --head` prints it)")  # fmt: skip


def executor_for(args) -> Executor:  # type: ignore[no-untyped-def]
    """The executor a command line asks for (the local one where the command takes no --executor)."""
    name, address = getattr(args, "executor", "local"), getattr(args, "address", None)
    if name == "ray":
        return RayExecutor(address, getattr(args, "jobs", None))
    if address is not None:
        raise RunError("--address names a Ray cluster: add --executor ray")
    return LocalExecutor()
