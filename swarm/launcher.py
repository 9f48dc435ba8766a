"""`swarm up`: a world and N agent processes, each its own OS process.

The launcher only starts, watches and stops processes; it follows the run on
the world's `state` key for the progress bar.  Every child runs in its own
process group so that Ctrl-C reaches it only through us, and every child is
ended (SIGTERM, then SIGKILL) before we return: no orphans, no hang.

An agent process that dies once the run ticks is, by default, a loss the run
survives (`_Losses`): one line says which, the world counts its agents lost as
it does for any agent that stops answering, and with `respawn` the same
command is started again for their places.  `strict`, and any death before
the run ticks (a process that cannot start), stops the run as a failure.

A process group, not a session: Linux's autogroup scheduler (on by default)
gives every session one equal share of the CPU, so a world in its own session
got as much CPU, with all its threads, as one single-threaded agent process:
at 100 agent processes on 2 cores lock-step ran some 20 % slower.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from agents.controllers import aot
from swarm.core import mesh, wire
from swarm.core.bus import open_client
from swarm.core.credentials import MONITOR, ROUTER, Identity, agent_name, identity_in
from swarm.core.credentials import make as make_credentials
from swarm.core.errors import RunError, raise_interrupt
from swarm.core.registry import resolve
from swarm.scenario import load_scenario
from world_server import WORLD_KINDS, kind_of, progress_keys, world_kind
from world_server.grid.params import PhysicsParams

ON_LOSS = ("go-on", "respawn", "strict")  # what an agent process that dies mid-run does to the run
MAX_RESPAWNS = 3  # with respawn: how often the agents of one process are given a new one


def _terminate(procs: list[subprocess.Popen], grace: float = 5.0) -> None:
    for p in procs:
        if p.poll() is None:
            p.send_signal(signal.SIGTERM)
    deadline = time.monotonic() + grace
    for p in procs:
        try:
            p.wait(timeout=max(0.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()


def swarm_up(
    scenario_ref: str, agents: int, controller: str | None, seed: int | None, run_id: str, listen: str,
    until: str = "foraged", max_iterations: int = 1_000_000, deadline: float = 2.0, progress: bool = True,
    per_process: int = 1, null: bool = False, mode: str = "lockstep", rate: float = 20.0,
    physics: PhysicsParams | None = None, record: str | None = None, viewer: str | None = None,
    world_args: list[str] | None = None, agent_args: list[str] | None = None, on_loss: str = "go-on",
    max_respawns: int = MAX_RESPAWNS, secure: bool = False, credentials: str | None = None,
) -> dict:  # fmt: skip
    """Run the swarm as processes; `per_process` agents share one agent process
    (`swarm agent --count`), `null` runs the benchmark floor (messaging only).
    `controller` None keeps the scenario's (an arena may mix controllers:
    each group's agents run its own).  `on_loss`: an agent process that dies
    mid-run is a loss the run goes on without ("go-on"), is replaced by a new
    one, at most `max_respawns` times for the agents of one process
    ("respawn"), or stops the run ("strict").  `secure` makes the run's
    credentials (swarm/core/credentials.py) or uses those in the folder `credentials`:
    the router checks every login and enforces swarm/core/acl.py's rules."""
    if agents % per_process:
        raise ValueError(f"{agents} agents do not split into processes of {per_process}")
    if on_loss not in ON_LOSS:
        raise ValueError(f"on_loss: expected one of {', '.join(ON_LOSS)}, got {on_loss!r}")
    # SIGTERM (docker stop, timeout, kill) must clean up like Ctrl-C does: raise so `finally` runs.
    previous = signal.signal(signal.SIGTERM, raise_interrupt)
    physics = physics or PhysicsParams()
    world_options = ["--until", until, "--max-iterations", str(max_iterations), "--deadline", str(deadline),
                     "--mode", mode, "--rate", str(rate), "--physics", physics.mode,
                     "--body-diameter", repr(physics.diameter)]  # fmt: skip
    if seed is not None:
        world_options += ["--seed", str(seed)]
    world_options += world_args or []
    if record:
        world_options += ["--record", record]
    if viewer:
        world_options += ["--viewer", viewer]
    try:
        return _swarm_up(
            scenario_ref,
            agents,
            controller,
            run_id,
            listen,
            world_options,
            progress,
            per_process,
            null,
            agent_args or [],
            _Losses(on_loss, max_respawns, let_go=3 * deadline + 10.0),
            credentials if credentials is not None or not secure else "",
        )
    finally:
        signal.signal(signal.SIGTERM, previous)


def prepare(scenario_ref: str | None = None, progress: bool = True, engine: bool = False,
            every_kind: bool = False) -> bool:  # fmt: skip
    """Compile everything a run needs before it starts: the agents' ahead-of-time
    step (in a subprocess, in parallel) and what the scenario's world kind warms
    up (its world and controller kernels; with `engine` its in-process engine);
    with `every_kind`, every world kind's, on its example scenario.  Returns
    whether the ahead-of-time build exists.  Container images run it at build time."""
    builder = start_agents_build(progress)
    # once here, so N agents starting together find the kernels in the cache
    if every_kind:
        for kind in WORLD_KINDS:
            resolve(kind.warm_up)(load_scenario(kind.example), engine)
    else:
        scenario = load_scenario(scenario_ref or world_kind().example)
        resolve(kind_of(scenario).warm_up)(scenario, engine)
    return finish_agents_build(builder)


def start_agents_build(progress: bool = True) -> subprocess.Popen | None:
    """The agents' ahead-of-time step, built in a subprocess when this source version has none yet (None:
    it has one); agent processes run it without numba (~35 MB instead of ~150)."""
    if aot.built() is not None:
        return None
    if progress:
        print("swarm: building the agents' compiled step (once per source version, about a minute)",
              file=sys.stderr)  # fmt: skip
    return subprocess.Popen([sys.executable, "-m", "agents.controllers.aot"], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)  # fmt: skip


def finish_agents_build(builder: subprocess.Popen | None) -> bool:
    """Wait for `start_agents_build`'s build (a failure is a note: agents fall back to the JIT); whether the
    step exists."""
    if builder is not None and builder.wait() != 0:
        print(f"swarm: note: the ahead-of-time build failed, agents use the JIT (more memory):\n"
              f"{builder.stderr.read()[-1500:]}", file=sys.stderr)  # fmt: skip
    return aot.built() is not None


def _agent_counts(scenario_ref: str, agents: int, controller: str | None) -> list[tuple[str, int]]:
    """(controller, agents) for every kind of agent process the run needs."""
    if controller is not None:
        return [(controller, agents)]
    return load_scenario(scenario_ref).agent_processes(agents)


def _swarm_up(scenario_ref, agents, controller, run_id, listen, world_options, progress, per_process, null,
              agent_args, losses: _Losses, credentials: str | None) -> dict:  # fmt: skip
    """`credentials`: None for a plain run, "" to make them, else the folder that holds them."""
    router_host = _router_host(listen) if credentials == "" else None  # a bad --listen: one line, before compiling
    prepare(scenario_ref, progress)
    python = [sys.executable, "-m", "swarm"]
    with tempfile.TemporaryDirectory(prefix="swarm-up-") as tmp:
        summary_file = Path(tmp) / "summary.json"
        world_cmd = [*python, "world", scenario_ref, "--agents", str(agents), "--run-id", run_id, "--listen", listen,
                     "--summary-file", str(summary_file), "--start-timeout", str(60 + 3 * agents), "--quiet",
                     *world_options]  # fmt: skip
        if controller is not None:
            world_cmd += ["--controller", controller]
        agent_cmds = []
        for name, n in _agent_counts(scenario_ref, agents, controller):
            cmd = [*python, "agent", "--controller", name, "--connect", listen, "--run-id", run_id,
                   "--count", str(per_process), *agent_args]  # fmt: skip
            agent_cmds += [cmd + (["--null"] if null else [])] * (n // per_process)
        if null:
            world_cmd.append("--null")
        folder = None
        if credentials is not None:
            folder = Path(credentials) if credentials else make_credentials(Path(tmp) / "credentials", len(agent_cmds),
                                                                            hosts=(router_host,))  # fmt: skip
            world_cmd, agent_cmds = _secured(folder, world_cmd, agent_cmds)
        children = _Children(Path(tmp), run_id)
        session = None
        try:
            world = children.start("the world", world_cmd)
            session = _connect(listen, world, identity_in(folder, MONITOR) if folder else None)
            rss = {}
            if session is not None:  # None: the world is already done (e.g. it resumed a finished run)
                for i, cmd in enumerate(agent_cmds):
                    children.start(f"agent process {i + 1}", cmd, agent=True)
                losses.follow(children, session, wire.Keys(run_id))
                rss = _follow(session, wire.Keys(run_id), children, agents, progress, losses)
            world.wait()
            if not summary_file.exists():  # exit 1 with a summary is an unfinished run, not a failure
                raise children.failure(world)
            summary = json.loads(summary_file.read_text())
            if session is not None:
                losses.last_look(_say)  # died as the run ended: said and counted, not replaced
            if rss:
                summary["agent_process_rss_mb"] = round(max(rss.values()) / 1024, 1)
            summary.update(losses.summary())
            grace = time.monotonic() + 10  # agents leave on the world's stop message; the rest are ended below
            for p in children.procs[1:]:
                with contextlib.suppress(subprocess.TimeoutExpired):
                    p.wait(timeout=max(0.0, grace - time.monotonic()))
            for line in children.told():  # the files go with the folder: said here, once the agents have left
                print(line, file=sys.stderr)
            return summary
        finally:
            if session is not None:
                session.close()
            _terminate(children.procs)


class _Children:
    """The launcher's processes, each with its standard error in a file, so
    that a failure is said in one line (the child's own last error) rather
    than as the child's output."""

    def __init__(self, folder: Path, run_id: str):
        self.folder, self.run_id = folder, run_id
        self.procs: list[subprocess.Popen] = []
        self.names: dict[int, str] = {}
        self.cmds: dict[int, list[str]] = {}  # pid -> the command it was started with (a replacement's)

    def start(self, name: str, cmd: list[str], agent: bool = False) -> subprocess.Popen:
        """Start a child; an agent process also writes its agents' ids once joined (`agent_ids`)."""
        i = len(self.procs)
        log = self.folder / f"child-{i}.err"
        told = ["--ids-file", str(self.folder / f"child-{i}.ids")] if agent else []
        with open(log, "wb") as err:
            p = subprocess.Popen([*cmd, *told], stdout=subprocess.DEVNULL, stderr=err, process_group=0)
        self.procs.append(p)
        self.names[p.pid] = name
        self.cmds[p.pid] = cmd
        return p

    def agents(self) -> list[subprocess.Popen]:
        return self.procs[1:]

    def agent_ids(self, p: subprocess.Popen) -> list[int] | None:
        """The ids of the agents an agent process ran, or None if they had not all joined."""
        try:
            return [int(a) for a in json.loads((self.folder / f"child-{self.procs.index(p)}.ids").read_text())]
        except (OSError, ValueError, TypeError):
            return None

    def told(self) -> list[str]:
        """What the agent processes told of their controllers (a controller that raised or answered
        NaN: agents.controllers.arena.StepGuard) and of the messages they refused, to say again when
        the run ends."""
        lines = []
        for i in range(1, len(self.procs)):
            text = (self.folder / f"child-{i}.err").read_text(errors="replace")
            lines += [line.strip() for line in text.splitlines()
                      if line.startswith(("swarm: controller ", "swarm: agent process refused"))]  # fmt: skip
        return lines

    def failure(self, p: subprocess.Popen) -> RunError:
        """The error to report for a failed child: its own last error line;
        the whole of its output is kept in a file named in the message."""
        return RunError(f"{self.names[p.pid]} failed: {self.cause(p)}; every process of the run was stopped")

    def cause(self, p: subprocess.Popen) -> str:
        """Why a child ended: its own last error line, or its exit status; a crash's whole output
        is kept in a file the line names."""
        i = self.procs.index(p)
        text = (self.folder / f"child-{i}.err").read_text(errors="replace")
        lines = [line.strip() for line in text.splitlines() if line.strip()]
        ours = [line for line in lines if line.startswith("swarm")]
        cause = (ours or lines or [f"it exited with status {p.returncode} and said nothing"])[-1]
        cause = cause.removeprefix("swarm: error: ").removeprefix("swarm: ")
        name = self.names[p.pid]
        where = ""
        if not ours and lines:  # not one of our errors (a crash): keep its output for the bug report
            kept = Path(tempfile.gettempdir()) / f"swarm-{self.run_id}-{name.replace(' ', '-')}.log"
            kept.write_text(text)
            where = f" (its output: {kept})"
        return f"{cause}{where}"


def _say(line: str) -> None:
    print(line, file=sys.stderr)


def _names(ids: list[int] | None) -> str:
    if ids is None:
        return "its agents had not joined"
    return f"agent{'s' if len(ids) != 1 else ''} {', '.join(map(str, ids))}"


class _Losses:
    """What becomes of an agent process that dies (exits with a status other than 0: a process
    the world told to stop exits 0).

    Before the run ticks, and always with "strict", it stops the run (RunError): a process that
    cannot start is a broken command or controller, not a robot lost.  Once the run ticks, one
    line names it, its agents and its exit status or last error line, and the run goes on: the
    world counts its agents lost (`agents_lost`) as soon as their liveliness tokens go.  With
    "respawn", once the world has let those agents go (they are no longer among its members, or
    `let_go` seconds have passed) the same command starts again: its agents take the free
    places (the grid: fresh bodies at the base; the arena: the lost bodies, driven on).  The
    agents of one process are given a new one at most `max_respawns` times, and a replacement
    that dies before its agents joined is not replaced (its controller would fail again).  When
    no agent process is left and none is coming, the world could only wait: RunError."""

    def __init__(self, on_loss: str, max_respawns: int, let_go: float):
        self.on_loss, self.max_respawns, self.let_go = on_loss, max_respawns, let_go
        self.ticking = False  # the world has ticked: deaths are losses from then on
        self.ending = False  # the world said it has ended: no replacement, and no agent is needed any more
        self.died = 0
        self.replaced = 0
        self.seen: set[int] = set()  # the pids of dead agent processes already dealt with
        self.generation: dict[int, int] = {}  # pid -> how many replacements came before it for its agents
        self.meant_for: dict[int, list[int]] = {}  # a replacement's pid -> the agents it was started for
        self.pending: list[tuple[subprocess.Popen, list[int], float]] = []  # (dead process, its agents, since)
        self.children: _Children | None = None
        self.session = self.keys = None

    def follow(self, children: _Children, session, keys: wire.Keys) -> None:
        self.children, self.session, self.keys = children, session, keys

    def check(self, say) -> None:
        """Deal with the agent processes that died since the last look; start the replacements due."""
        children = self.children
        dead = [p for p in children.agents() if p.pid not in self.seen and p.poll() not in (None, 0)]
        for p in dead:
            self.seen.add(p.pid)
            if self.on_loss == "strict" or not self.ticking:
                raise children.failure(p)
        said = [self._lost(p) for p in dead]  # (which died and how, what follows)
        if not self.ending and not self.pending and all(p.poll() not in (None, 0) for p in children.agents()):
            for what, fate in said[:-1]:
                say(f"swarm: {what}; {fate}")
            what, fate = said[-1] if said else ("every agent process has died", "")
            if self.on_loss != "respawn":
                fate = "it was the last agent process (--respawn replaces them)"
            raise RunError(f"{what}; {fate}; with no agent process left the world cannot go on; every process "
                           "of the run was stopped")  # fmt: skip
        for what, fate in said:
            say(f"swarm: {what}; {fate}")
        if self.pending:
            self._respawn(say)

    def last_look(self, say) -> None:
        """Once the world has ended: the processes that died in its last moments, said and counted."""
        if self.on_loss == "strict" or not self.ticking:
            return
        for p in self.children.agents():
            if p.pid not in self.seen and p.poll() not in (None, 0):
                self.seen.add(p.pid)
                self.died += 1
                say(f"swarm: {self._what(p)}")

    def summary(self) -> dict:
        """The launcher's own keys of the summary, only when an agent process died: a run without a
        loss has the summary it always had."""
        if not self.died:
            return {}
        out = {"agent_processes_died": self.died}
        if self.on_loss == "respawn":
            out["agent_processes_replaced"] = self.replaced
        return out

    def _what(self, p: subprocess.Popen) -> str:
        ids = self.children.agent_ids(p)
        whose = _names(ids) if ids is not None or p.pid not in self.meant_for else \
            f"for {_names(self.meant_for[p.pid])}, not joined yet"  # fmt: skip
        return f"{self.children.names[p.pid]} ({whose}) died: {self.children.cause(p)}"

    def _lost(self, p: subprocess.Popen) -> tuple[str, str]:
        """A death counted: which process died and how, and what follows."""
        self.died += 1
        what = self._what(p)
        ids = self.children.agent_ids(p)
        done = self.generation.get(p.pid, 0)
        if self.on_loss != "respawn":
            return what, "the run goes on without its agents"
        if ids is None:
            return what, "not replaced, as it died before its agents joined"
        if done >= self.max_respawns:
            return what, (f"not replaced: its agents were given a new process {done} times already "
                          f"(--max-respawns {self.max_respawns})")  # fmt: skip
        self.pending.append((p, ids, time.monotonic()))
        return what, "a replacement follows"

    def _respawn(self, say) -> None:
        try:
            info = wire.world_info(self.session, self.keys, timeout=1.0)
        except Exception:  # zenoh while the world goes: try again at the next look
            info = None
        if info is not None and info.get("ended"):  # its agents are leaving on its stop message
            self.ending = True
            self.pending.clear()
            return
        members = set(info.get("members", [])) if info is not None else None
        for entry in list(self.pending):
            dead, ids, since = entry
            still = members is None or bool(members.intersection(ids))
            if still and time.monotonic() - since < self.let_go:
                continue  # the world has not let them go yet: a join now would find the swarm full
            self.pending.remove(entry)
            children = self.children
            name = f"agent process {len(children.agents()) + 1}"
            new = children.start(name, children.cmds[dead.pid], agent=True)
            self.generation[new.pid] = self.generation.get(dead.pid, 0) + 1
            self.meant_for[new.pid] = ids
            self.replaced += 1
            say(f"swarm: {name} started in place of {children.names[dead.pid]} for {_names(ids)} "
                f"(replacement {self.generation[new.pid]} of at most {self.max_respawns})")  # fmt: skip


def _secured(folder: Path, world_cmd: list[str], agent_cmds: list[list[str]]):
    """The commands, each given its own identity: the world hosts the router, agent process i is `agent<i>`."""
    names = [ROUTER, *(agent_name(i + 1) for i in range(len(agent_cmds)))]
    for name in names:
        identity_in(folder, name)  # a one-line error now, not a child's failure later
    world_cmd = [*world_cmd, "--credentials", str(folder / ROUTER)]
    agent_cmds = [[*cmd, "--credentials", str(folder / name)] for cmd, name in zip(agent_cmds, names[1:], strict=True)]
    return world_cmd, agent_cmds


def _router_host(listen: str) -> str:
    """The name the router's certificate must carry: the host of --listen."""
    try:
        return mesh.split(listen)[1]
    except ValueError as exc:
        raise RunError(f"--listen {exc}") from None


def _connect(listen: str, world: subprocess.Popen, identity: Identity | None = None, timeout: float = 300.0):
    """A client session to the world's router, or None if the world exits first."""
    deadline = time.monotonic() + timeout
    while world.poll() is None:
        try:
            return open_client(listen, timeout=2.0, identity=identity)
        except ConnectionError:
            if time.monotonic() > deadline:
                raise
    return None


def rss_kb(pid: int) -> int:
    """A process's resident memory in kB (0 once it is gone)."""
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return 0


def _follow(session, keys: wire.Keys, children: _Children, agents: int, progress: bool, losses: _Losses) -> dict:
    """Show progress until the world exits; return each agent process's peak RSS (kB).
    An agent process that dies is dealt with as `losses` says (RunError to stop the run)."""
    import queue

    from tqdm import tqdm

    world, procs = children.procs[0], children.procs
    rss: dict[int, int] = {}
    states: queue.Queue = queue.Queue()
    sub = session.declare_subscriber(keys.state, states.put)
    bar = tqdm(desc="done", unit="", disable=not progress, leave=False)

    def say(line: str) -> None:
        tqdm.write(line, file=sys.stderr)

    next_look = 0.0  # when to look at the agents' processes again (deaths, peak memory)
    try:
        while world.poll() is None:
            try:
                msg = wire.unpack(states.get(timeout=0.5).payload.to_bytes())
            except queue.Empty:
                msg = None
            if msg is None:
                losses.check(say)
                continue
            if isinstance(msg, wire.Rejected):
                continue
            if time.monotonic() >= next_look and msg.get("tick", 0) > 0:  # the world ticks ten times this a second
                next_look = time.monotonic() + 1.0
                losses.ticking = True  # state messages come from ticks
                losses.check(say)
                for p in procs[1:]:
                    rss[p.pid] = max(rss.get(p.pid, 0), rss_kb(p.pid))
            done, total = progress_keys(msg)
            bar.total = msg.get(total)
            bar.n = msg.get(done, 0)
            bar.set_postfix(tick=msg.get("tick"), alive=f"{msg.get('agents_alive')}/{agents}",
                            tps=msg.get("ticks_per_second"))  # fmt: skip
            bar.refresh()
    finally:
        bar.close()
        sub.undeclare()
    return rss


def default_listen() -> str:
    return os.environ.get("SWARM_LISTEN", "tcp/127.0.0.1:7447")
