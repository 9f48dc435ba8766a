"""What a soak's numbers come to: memory at a moment and its growth, ticks missing from a recording, losses
counted.  Pure functions of the samples, the recorded ticks and the summary, so each is tested on its own."""

from __future__ import annotations

import statistics
from collections.abc import Sequence

import numpy as np

TARGET_GROWTH = 5.0  # % resident memory may grow over the measured span (issue 49: <= 5 % over the last 20 minutes)
SPAN_SHARE = 2 / 3  # the measured span: the run's last two thirds (30 min: the last 20)


def rss_at(samples: Sequence[tuple[float, float]], at: float, window: float) -> float | None:
    """The median of the (seconds, kB) samples within `window` seconds either side of `at` (one sample is
    noise: the allocator returns memory in steps); None when none falls there."""
    near = [kb for t, kb in samples if abs(t - at) <= window]
    return statistics.median(near) if near else None


def span(duration: float) -> tuple[float, float]:
    """(start, end) in seconds of the span growth is measured over: the last two thirds of the run."""
    return duration * (1 - SPAN_SHARE), duration


def growth(samples: Sequence[tuple[float, float]], duration: float, window: float) -> dict:
    """Resident memory at the span's start and end (kB, each a median over `window`) and the growth in %.
    The end's samples are the last `window` seconds' (nothing is sampled after the run)."""
    start, end = span(duration)
    first = rss_at(samples, start, window)
    last = rss_at([s for s in samples if s[0] >= end - 2 * window], end, 2 * window)
    if first is None or last is None or first <= 0:
        return {"start_kb": first, "end_kb": last, "growth_pct": None}
    return {"start_kb": round(first), "end_kb": round(last), "growth_pct": round(100 * (last - first) / first, 2)}


def missing_ticks(recorded: np.ndarray, played: int) -> list[int]:
    """The ticks 0..played-1 a recording lacks."""
    return np.setdiff1d(np.arange(played), np.asarray(recorded, np.int64)).tolist()


def losses(summary: dict, kills: int, per_process: int) -> dict:
    """Whether the run counted every kill: a dead agent process, a replacement, and its agents lost.  The
    world also loses the agents of a live process that misses `max_misses` real-time ticks in a row (on a
    starved machine): those are counted too, and shown as `beyond_kills`."""
    died = summary.get("agent_processes_died", 0)
    replaced = summary.get("agent_processes_replaced", 0)
    lost = summary.get("agents_lost", 0)
    counted = died == kills and replaced == kills and lost >= kills * per_process
    return {"kills": kills, "died": died, "replaced": replaced, "agents_lost": lost,
            "beyond_kills": lost - kills * per_process, "all_counted": counted}  # fmt: skip


def met(result: dict) -> bool:
    """The soak's targets: every long-lived process within TARGET_GROWTH, no tick missing, every loss counted."""
    grown = [g["growth_pct"] for g in result["memory"].values() if g["verdict"]]
    return (
        all(g is not None and g <= TARGET_GROWTH for g in grown)
        and not result["missing_ticks"]
        and result["losses"]["all_counted"]
    )
