"""Watching a run from outside: `swarm status`, `swarm monitor`, `swarm router`.

These are the pieces a deployment needs besides the world and the agents
(compose.yaml uses all three): a zenoh router on its own, a probe that says
whether a router or a world answers (health checks), and a monitor that
follows a run on its `state` key and prints the summary when the world says
the run has ended.  All of them only read the run's key space.
"""

from __future__ import annotations

import queue
import signal
import sys
import threading
import time

from swarm.core import wire
from swarm.core.bus import open_bridge, open_client, open_router
from swarm.core.credentials import Identity
from swarm.core.errors import RunError, one_line
from swarm.core.mesh import Mesh, listed, local, others
from swarm.core.wire import world_info
from world_server import progress_keys


def status(connect: str, run_id: str, router_only: bool = False, timeout: float = 3.0,
           identity: Identity | None = None) -> dict | None:  # fmt: skip
    """{"router": ...} if only the router is asked, else the world's info; None if nobody answers."""
    try:
        session = open_client(connect, timeout=timeout, identity=identity)
    except ConnectionError:
        return None
    try:
        if router_only:
            return {"router": connect}
        return world_info(session, wire.Keys(run_id), timeout=timeout)
    finally:
        session.close()


MESH_LOOK_EVERY = 5.0  # s between looks at the --mesh names for routers found after this one opened


def serve_router(listen: str, identity: Identity | None = None, mesh: tuple[str, ...] = ()) -> None:
    """A bare zenoh router until SIGTERM or Ctrl-C; with `identity` (the `router` folder) it checks
    logins and enforces the access rules; linked to every other router each `mesh` name lists."""
    if identity is not None and mesh and not all(e.startswith("tls/") for e in (listen, *mesh)):
        raise RunError("a secure mesh of routers needs TLS links, which show each router's certificate: give "
                       "--listen tls/... and --mesh tls/...")  # fmt: skip
    routers = [found for name in mesh for found in others(name)]
    session = open_router(listen, identity, routers)
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    linked = f", linked to {', '.join(routers)}" if routers else ""
    print(f"swarm: zenoh router listening on {listen}{linked}", file=sys.stderr, flush=True)
    keeper = Mesh(session, lambda: listed(mesh), routers, lambda far: open_bridge(local(listen), far, identity))
    try:
        while not stop.wait(MESH_LOOK_EVERY):  # without --mesh names every look tells nothing (None)
            try:
                bridged = keeper.check()
            except Exception as exc:  # a look that fails is tried again; the router serves on
                print(f"swarm: could not look for other routers: {one_line(exc)}", file=sys.stderr, flush=True)
                continue
            for far in bridged:
                print(f"swarm: zenoh router bridging to {far}, listed with no link to this router", file=sys.stderr,
                      flush=True)  # fmt: skip
    finally:
        keeper.close()
        session.close()


def monitor(connect: str, run_id: str, progress: bool, log_every: float = 5.0, start_timeout: float = 600.0,
            identity: Identity | None = None) -> dict:  # fmt: skip
    """Follow a run until its world says it has ended; returns the final summary.

    Progress goes to stderr: a bar on a terminal, else one line every
    `log_every` seconds (container logs).  The end is read from the world's
    info, polled once a second, so a monitor that starts late, even after the
    run, still gets the summary."""
    from tqdm import tqdm

    keys = wire.Keys(run_id)
    session = open_client(connect, timeout=start_timeout, identity=identity)
    states: queue.Queue = queue.Queue()
    sub = session.declare_subscriber(keys.state, states.put)
    bar = tqdm(desc="delivered", unit="unit", disable=not progress, leave=False)
    last_log = seen = 0.0
    deadline = time.monotonic() + start_timeout
    try:
        while True:
            info = world_info(session, keys)
            if info is None and not seen and time.monotonic() > deadline:
                raise TimeoutError(f"no world answered on {keys.info} for {start_timeout:g} s; is it running?")
            if info is not None:
                seen = True
                if info.get("ended"):
                    return {k: v for k, v in info.items() if k not in ("type", "members", "ended")}
            latest = None
            try:
                while True:
                    msg = wire.unpack(states.get(timeout=0.05 if latest else 1.0).payload.to_bytes())
                    if isinstance(msg, dict):
                        latest = msg
            except queue.Empty:
                pass
            state = latest or info
            if state is None:
                continue
            waiting = state.get("tick", 0) == 0 and info is not None  # the world waits for its first agents
            done, total = progress_keys(state)
            if progress:
                bar.set_description(f"waiting for agents {info['agents_alive']}/{info['start_with']}"
                                    if waiting else "done")  # fmt: skip
                bar.total = state.get(total)
                bar.n = state.get(done, 0)
                bar.set_postfix(tick=state.get("tick"), alive=state.get("agents_alive"),
                                tps=state.get("ticks_per_second"))  # fmt: skip
                bar.refresh()
            elif time.monotonic() - last_log >= log_every:
                last_log = time.monotonic()
                line = (f"waiting for agents: {info['agents_alive']} of {info['start_with']} joined" if waiting else
                        f"tick {state.get('tick')}: {done} {state.get(done)}/{state.get(total)}, "
                        f"{state.get('agents_alive')} agents, "
                        f"{state.get('ticks_per_second')} ticks/s")  # fmt: skip
                print(line, file=sys.stderr, flush=True)
    finally:
        bar.close()
        sub.undeclare()
        session.close()
