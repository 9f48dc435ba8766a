"""The processes of a `swarm up` started in this process, as /proc shows them: which is the world, which
are agent processes, whether an agent process's agents have joined, and how much memory each holds.

The launcher keeps its children to itself; the soak finds them as any outside observer would (children of
this process whose command line names the run), so the run it watches is the launcher's own, unchanged.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from swarm.launcher import rss_kb

try:
    import psutil
except ImportError:  # /proc's VmRSS says the same
    psutil = None


@dataclass(frozen=True)
class Child:
    pid: int
    role: str  # "world" or "agent"
    started: int  # clock ticks after boot (/proc/<pid>/stat field 22): the order processes started in
    ids_file: Path | None  # where an agent process writes its agents' ids once they joined


def resident_kb(pid: int) -> int:
    """Resident memory in kB; 0 once the process is gone."""
    if psutil is None:
        return rss_kb(pid)
    try:
        return psutil.Process(pid).memory_info().rss // 1024
    except psutil.Error:
        return 0


def _stat(pid: int) -> tuple[int, int] | None:
    """(parent pid, start time) of a live process, None if it is gone or a zombie."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    fields = text[text.rindex(")") + 2 :].split()  # the name in parentheses may hold spaces
    if fields[0] == "Z":
        return None
    return int(fields[1]), int(fields[19])


def _argv(pid: int) -> list[str]:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().decode(errors="replace").split("\0")
    except OSError:
        return []


def children(run_id: str, parent: int | None = None) -> list[Child]:
    """The live world and agent processes of run `run_id` that `parent` (this process) started, oldest first."""
    parent = os.getpid() if parent is None else parent
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit() or (stat := _stat(int(entry.name))) is None or stat[0] != parent:
            continue
        argv = _argv(int(entry.name))
        if "--run-id" not in argv or argv[argv.index("--run-id") + 1] != run_id:
            continue
        role = next((r for r in ("world", "agent") if r in argv[:4]), None)
        if role is None:
            continue
        ids = Path(argv[argv.index("--ids-file") + 1]) if "--ids-file" in argv else None
        found.append(Child(int(entry.name), role, stat[1], ids))
    return sorted(found, key=lambda c: (c.started, c.pid))


def joined(child: Child) -> bool:
    """Whether an agent process's agents have joined: it writes their ids only then (`swarm agent --ids-file`)."""
    return child.ids_file is not None and child.ids_file.exists()
