"""What a flock is measured by, from a run's summary (each robot's final pose): metrics for
`swarm sweep` ("swarm_flocking.metrics:polarization")."""

from __future__ import annotations

import numpy as np


def _poses(summary: dict) -> np.ndarray:
    return np.array([r["pose"] for r in summary["robots"] if r.get("pose") is not None], np.float64).reshape(-1, 3)


def polarization(summary: dict) -> float:
    """Vicsek's order parameter: the length of the robots' mean heading vector, 1 when all head
    the same way, about 1/sqrt(N) for random headings."""
    theta = _poses(summary)[:, 2]
    return float(np.hypot(np.cos(theta).mean(), np.sin(theta).mean()))


def spread(summary: dict) -> float:
    """The robots' mean distance from their centroid, metres."""
    xy = _poses(summary)[:, :2]
    return float(np.linalg.norm(xy - xy.mean(axis=0), axis=1).mean())
