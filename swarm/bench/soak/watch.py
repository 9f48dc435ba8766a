"""The soak's second thread, beside the launcher's run: once every agent process has joined it samples the
processes' resident memory every `interval` seconds and kills the longest-lived joined agent process with
SIGKILL every `kill_every` seconds (the launcher's respawn starts its replacement, the youngest, so the
kills go round every place in turn).  Only joined processes are killed: a replacement that dies before its
agents joined is, by the launcher's rule, not replaced."""

from __future__ import annotations

import os
import signal
import threading
import time

from tqdm import tqdm

from swarm.bench.soak import procs

ROLES = ("world", "launcher", "agent")  # what is sampled: the world (its router inside), us, an agent process (mean)


class Watch(threading.Thread):
    def __init__(self, run_id: str, processes: int, duration: float, kill_every: float, kill_until: float,
                 interval: float, progress: bool):  # fmt: skip
        super().__init__(name="soak-watch", daemon=True)
        self.run_id, self.processes, self.duration = run_id, processes, duration
        self.kill_every, self.kill_until, self.interval, self.progress = kill_every, kill_until, interval, progress
        self.samples: dict[str, list[tuple[float, float]]] = {r: [] for r in ROLES}  # role -> (s since start, kB)
        self.kill_times: list[float] = []
        self.error: BaseException | None = None
        self.started_at: float | None = None  # monotonic: every agent process had joined
        self.ended_at: float | None = None
        self._done = threading.Event()

    def stop(self) -> None:
        self._done.set()
        self.join(timeout=10)
        if self.error is not None:
            raise self.error

    def run(self) -> None:
        try:
            if self._wait_joined():
                self._watch()
        except BaseException as exc:  # said by stop(), in the thread that runs the launcher
            self.error = exc
        finally:
            self.ended_at = time.monotonic()

    def _wait_joined(self) -> bool:
        while not self._done.wait(0.2):
            agents = [c for c in procs.children(self.run_id) if c.role == "agent"]
            if len(agents) == self.processes and all(map(procs.joined, agents)):
                self.started_at = time.monotonic()
                return True
        return False

    def _watch(self) -> None:
        next_sample, next_kill = 0.0, self.kill_every
        with tqdm(total=round(self.duration), desc="soak", unit="s", disable=not self.progress, leave=False) as bar:
            while not self._done.wait(0.2):
                now = time.monotonic() - self.started_at
                if now >= next_sample:
                    self._sample(now)
                    next_sample += self.interval
                    bar.n = min(round(now), bar.total)
                    world = self.samples["world"][-1:] or [(0, 0)]
                    bar.set_postfix(kills=len(self.kill_times), world_mb=round(world[0][1] / 1024))
                if now >= next_kill and now <= self.kill_until and self._kill_oldest(now):
                    next_kill = max(next_kill + self.kill_every, now + self.kill_every / 2)

    def _sample(self, now: float) -> None:
        """One sample of each role, while the world runs (after it, the processes are only leaving)."""
        children = procs.children(self.run_id)
        world = [procs.resident_kb(c.pid) for c in children if c.role == "world"]
        if not world or not world[0]:
            return
        self.samples["world"].append((now, world[0]))
        self.samples["launcher"].append((now, procs.resident_kb(os.getpid())))
        if agents := [kb for c in children if c.role == "agent" and (kb := procs.resident_kb(c.pid))]:
            self.samples["agent"].append((now, sum(agents) / len(agents)))

    def _kill_oldest(self, now: float) -> bool:
        """SIGKILL the longest-lived agent process whose agents joined; False when none has (yet)."""
        joined = [c for c in procs.children(self.run_id) if c.role == "agent" and procs.joined(c)]
        if not joined:
            return False
        os.kill(joined[0].pid, signal.SIGKILL)
        self.kill_times.append(round(now, 1))
        return True
