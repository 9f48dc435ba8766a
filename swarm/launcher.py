"""`swarm up`: a world and N agent processes, each its own OS process.

The launcher only starts, watches and stops processes; it follows the run on
the world's `state` key for the progress bar.  Every child runs in its own
session so that Ctrl-C reaches it only through us, and every child is ended
(SIGTERM, then SIGKILL) before we return: no orphans, no hang.
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

from agents.controllers import warm_up
from swarm import protocol as proto
from swarm.bus import open_client


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
    scenario_ref: str, agents: int, controller: str, seed: int | None, run_id: str, listen: str,
    until: str = "foraged", max_iterations: int = 1_000_000, deadline: float = 2.0, progress: bool = True,
) -> dict:  # fmt: skip
    warm_up()  # once here, so N agents starting together find it in the cache
    python = [sys.executable, "-m", "swarm"]
    with tempfile.TemporaryDirectory(prefix="swarm-up-") as tmp:
        summary_file = Path(tmp) / "summary.json"
        world_cmd = [*python, "world", scenario_ref, "--agents", str(agents), "--controller", controller,
                     "--run-id", run_id, "--listen", listen, "--until", until, "--max-iterations",
                     str(max_iterations), "--deadline", str(deadline), "--summary-file", str(summary_file)]  # fmt: skip
        if seed is not None:
            world_cmd += ["--seed", str(seed)]
        agent_cmd = [*python, "agent", "--controller", controller, "--connect", listen, "--run-id", run_id]
        quiet = {"stdout": subprocess.DEVNULL, "start_new_session": True}
        procs: list[subprocess.Popen] = []
        session = None
        try:
            world = subprocess.Popen(world_cmd, **quiet)
            procs.append(world)
            session = open_client(listen, timeout=60.0)
            procs += [subprocess.Popen(agent_cmd, **quiet) for _ in range(agents)]
            _follow(session, proto.Keys(run_id), world, procs, agents, progress)
            world.wait()
            if world.returncode != 0 or not summary_file.exists():
                raise RuntimeError(
                    f"the world process failed (exit {world.returncode}); run `swarm world` alone to see why"
                )
            summary = json.loads(summary_file.read_text())
            for p in procs[1:]:  # agents leave on the world's stop message
                with contextlib.suppress(subprocess.TimeoutExpired):
                    p.wait(timeout=10)
            return summary
        finally:
            if session is not None:
                session.close()
            _terminate(procs)


def _follow(session, keys: proto.Keys, world: subprocess.Popen, procs, agents: int, progress: bool) -> None:
    import queue

    from tqdm import tqdm

    states: queue.Queue = queue.Queue()
    sub = session.declare_subscriber(keys.state, states.put)
    bar = tqdm(desc="delivered", unit="unit", disable=not progress, leave=False)
    try:
        while world.poll() is None:
            try:
                msg = proto.unpack(states.get(timeout=0.5).payload.to_bytes())
            except queue.Empty:
                if any(p.poll() not in (None, 0) for p in procs[1:]) and progress:
                    bar.set_postfix_str("an agent process exited")
                continue
            if isinstance(msg, proto.Rejected):
                continue
            bar.total = msg.get("total")
            bar.n = msg.get("delivered", 0)
            bar.set_postfix(tick=msg.get("tick"), alive=f"{msg.get('agents_alive')}/{agents}",
                            tps=msg.get("ticks_per_second"))  # fmt: skip
            bar.refresh()
    finally:
        bar.close()
        sub.undeclare()


def default_listen() -> str:
    return os.environ.get("SWARM_LISTEN", "tcp/127.0.0.1:7447")
