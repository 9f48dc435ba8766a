"""Every publication of a run, for `get <share>/**`, kept across a restarted world.

Each publication the world passes on is appended to `<state-dir>/<run-id>.shared.msgpack`
as [tick, share, agent, payload].  A resumed run keeps the records written
before its saved tick and drops the rest (the resumed run publishes those
again), so a query after a restart replays the whole run, each publication
once.  A record cut short by a kill is where reading stops.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path
from typing import Any

import msgpack


class SharedHistory:
    def __init__(self, path: Path | None):
        self.path = path
        self.items: dict[tuple[str, int], list[bytes]] = {}
        self._file = None

    def open(self, keep_before: int | None) -> None:
        """Start the file: afresh (`keep_before` None), or keeping the records of ticks before `keep_before`."""
        if self.path is None or self._file is not None:
            return
        kept = self._read(keep_before) if keep_before is not None else []
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with open(self.path, "wb") as f:
            for record in kept:
                f.write(msgpack.packb(record, use_bin_type=True))
        for _, share, agent, payload in kept:
            self.items.setdefault((share, agent), []).append(payload)
        self._file = open(self.path, "ab")  # noqa: SIM115 - held for the run, closed by close()

    def _read(self, keep_before: int) -> list[list]:
        if not self.path.exists():
            return []
        kept = []
        unpacker = msgpack.Unpacker(raw=False, max_buffer_size=1 << 30)
        unpacker.feed(self.path.read_bytes())
        try:
            for record in unpacker:
                if not _is_record(record):
                    break
                if record[0] < keep_before:
                    kept.append(record)
        except (msgpack.ExtraData, msgpack.FormatError, msgpack.StackError, ValueError):
            pass  # a record cut short by a kill: the rest is published again
        return kept

    def add(self, tick: int, share: str, agent: int, payload: bytes) -> None:
        self.items.setdefault((share, agent), []).append(payload)
        if self._file is not None:
            self._file.write(msgpack.packb([tick, share, agent, payload], use_bin_type=True))

    def flush(self) -> None:
        """With every save of the world's state: what the saved state has passed on is on disk."""
        if self._file is not None:
            self._file.flush()
            os.fsync(self._file.fileno())

    def of(self, share: str) -> list[tuple[int, list[bytes]]]:
        return [(a, history) for (s, a), history in sorted(self.items.items()) if s == share]

    def close(self) -> None:
        if self._file is not None:
            self.flush()
            self._file.close()
            self._file = None


def _is_record(record) -> bool:
    """[tick, share, agent, payload], as `add` writes it."""
    if not (isinstance(record, list) and len(record) == 4):
        return False
    tick, share, agent, payload = record
    return type(tick) is int and isinstance(share, str) and type(agent) is int and isinstance(payload, bytes)


class ShareLog:
    """Per agent, how many publications and a digest of them in order: equal in
    both runtimes when every robot published the same bytes at the same ticks."""

    def __init__(self) -> None:
        self.count: dict[int, int] = {}
        self.digest: dict[int, str] = {}  # chained: sha1(previous digest, tick, share, payload)

    def add(self, tick: int, shared: list[tuple[int, str, bytes]]) -> None:
        for a, share, payload in shared:
            h = hashlib.sha1(f"{self.digest.get(a, '')}:{tick}:{share}:{len(payload)}:".encode())
            h.update(payload)
            self.digest[a] = h.hexdigest()
            self.count[a] = self.count.get(a, 0) + 1

    def of(self, agent: int) -> dict[str, Any] | None:
        if agent not in self.count:
            return None
        return {"messages": self.count[agent], "digest": self.digest[agent][:16]}

    def state(self) -> dict[str, list]:
        """What a saved world keeps (JSON): a chained digest goes on from its last value."""
        return {"agents": sorted(self.count), "count": [self.count[a] for a in sorted(self.count)],
                "digest": [self.digest[a] for a in sorted(self.count)]}  # fmt: skip

    def restore(self, state: dict[str, list]) -> None:
        self.count = dict(zip(state["agents"], state["count"], strict=True))
        self.digest = dict(zip(state["agents"], state["digest"], strict=True))
