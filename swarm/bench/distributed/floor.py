"""The bare lock-step floor over zenoh on this machine, measured as
shared/probes/lockstep_floor.py measures it.

A router in this process publishes one small observation to each of N agent
processes per tick and waits until every one has answered; each agent process
answers every observation with a small action and does nothing else (no
decoding, no world work).  No runtime can pass this number; `swarm bench
distributed` reports its own ticks per second as a share of it, measured in
the same command.

    python -m swarm.bench.distributed.floor 100 300
"""

from __future__ import annotations

import multiprocessing as mp
import sys
import threading
import time

from swarm.core.bus import open_client, open_router

OBS = b"obs-payload-64-bytes" * 3
ACT = b"act-payload-32-bytes-xxxxxxxxxxx"


def _agent(endpoint: str, i: int, ticks: int) -> None:
    session = open_client(endpoint)
    pub = session.declare_publisher(f"floor/agents/{i}/act")
    sub = session.declare_subscriber(f"floor/agents/{i}/obs")  # a FIFO channel
    pub.put(b"ready")
    for _ in range(ticks):
        pub.put(sub.recv().payload.to_bytes()[:8] + ACT)
    time.sleep(0.5)
    session.close()


def floor(processes: int, ticks: int = 300, endpoint: str = "tcp/127.0.0.1:17555") -> dict:
    """Ticks per second of the bare exchange with `processes` agent processes."""
    session = open_router(endpoint)
    lock, got = threading.Condition(), [0]

    def on_act(_sample) -> None:
        with lock:
            got[0] += 1
            lock.notify()

    sub = session.declare_subscriber("floor/agents/*/act", on_act)
    pubs = [session.declare_publisher(f"floor/agents/{i}/obs") for i in range(processes)]
    ctx = mp.get_context("spawn")
    procs = [ctx.Process(target=_agent, args=(endpoint, i, ticks), daemon=True) for i in range(processes)]
    try:
        for p in procs:
            p.start()
        deadline = time.monotonic() + 120
        with lock:
            while got[0] < processes:
                lock.wait(1)
                dead = sum(p.exitcode is not None for p in procs)
                if dead or time.monotonic() > deadline:
                    raise TimeoutError(f"only {got[0]} of {processes} floor processes started ({dead} exited)")
            got[0] = 0
        latency = []
        started = time.perf_counter()
        for tick in range(ticks):
            t = time.perf_counter()
            for pub in pubs:
                pub.put(tick.to_bytes(8, "little") + OBS)
            with lock:
                while got[0] < processes:
                    if not lock.wait(5):
                        raise TimeoutError(f"a floor process stopped answering at tick {tick}")
                got[0] = 0
            latency.append(time.perf_counter() - t)
        seconds = time.perf_counter() - started
    finally:
        for p in procs:
            p.join(10)
            if p.is_alive():
                p.kill()
        sub.undeclare()
        session.close()
    latency.sort()
    return {"processes": processes, "ticks": ticks, "ticks_per_second": round(ticks / seconds, 2),
            "tick_ms_p50": round(latency[len(latency) // 2] * 1e3, 3),
            "tick_ms_p99": round(latency[int(len(latency) * 0.99)] * 1e3, 3)}  # fmt: skip


if __name__ == "__main__":
    print(floor(int(sys.argv[1]), int(sys.argv[2]) if len(sys.argv) > 2 else 300))
