"""Range and bearing: the neighbours a robot hears, and what they broadcast (ARGoS's e-puck and
foot-bot range-and-bearing sensor and actuator; Gutierrez et al. 2009's e-puck board).

Each robot broadcasts `payload` bytes every tick (a controller's optional `broadcast()`:
agents/controllers/arena.py); at the next tick every robot within `range` of it, and in its line of
sight, reads its distance, its bearing and those bytes.  No identity comes with a message, as on
the real board: a controller that needs one puts it in its payload."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from world_server.arena.face.sensors.base import DEG, Reading, Sensor

RANGE, BEARING = 8, 9  # noise streams: each message's distance error, its bearing error
DENSE_UP_TO = 256  # robots in the world up to which every pair is tried; above, a k-d tree finds the pairs
MAX_PAYLOAD = 65536  # bytes a robot may broadcast per tick (the wire's bound on one message)


@dataclass(frozen=True)
class RangeAndBearing(Sensor):
    """The `max_neighbours` nearest robots within `range` (centre to centre, nearest first by the
    true distance), each with its distance (times 1 + a normal error of relative std `range_noise`),
    its bearing from the heading (in [-pi, pi), plus a normal error of std `bearing_noise`) and the
    `payload` bytes it broadcast at the previous tick.  With `occlusion`, a neighbour is heard only
    when nothing (a wall, a box, another robot) crosses the line between the two centres, as ARGoS's
    medium checks (one compiled ray per pair within range).  Rows past `rab_count` are padding:
    distance +inf (so "nearer than x" tests need no count), bearing 0, data 0."""

    name = "range_and_bearing"
    rank = 9
    streams = (RANGE, BEARING)

    range: float = 0.8  # m: the e-puck board's 80 cm (ARGoS's e-puck RAB range)
    max_neighbours: int = 16  # a fixed count, so the reading has a fixed shape
    range_noise: float = 0.05  # relative std of a distance, ours: the board's error grows with distance
    bearing_noise: float = 5 * DEG  # std, ours: the sonar's bearing error
    payload: int = 4  # bytes per message (ARGoS's e-puck RAB default data size: 4)
    occlusion: bool = True  # walls, boxes and robots between two robots cut their link

    def check(self, model) -> None:
        if not (self.range > 0 and math.isfinite(self.range)):
            raise ValueError(f"range: expected a positive distance in metres, got {self.range}")
        for f in ("range_noise", "bearing_noise"):
            if not (getattr(self, f) >= 0 and math.isfinite(getattr(self, f))):
                raise ValueError(f"{f}: expected a finite std of at least 0, got {getattr(self, f)}")
        if self.payload > MAX_PAYLOAD:
            raise ValueError(f"payload: expected at most {MAX_PAYLOAD} bytes, got {self.payload}")

    def read(self, r: Reading) -> dict[str, np.ndarray]:
        n, k = len(r.robots), self.max_neighbours
        row, other, distance, bearing = self.heard(r.robots, r.state)
        slot = _slots(row)
        keep = slot < k
        row, other, distance, bearing, slot = row[keep], other[keep], distance[keep], bearing[keep], slot[keep]
        factor = r.noise.factor(self.name)
        if factor and self.range_noise:
            distance = np.maximum(distance * (1.0 + r.normal(RANGE, k)[row, slot] * self.range_noise * factor), 0.0)
        if factor and self.bearing_noise:
            bearing = bearing + r.normal(BEARING, k)[row, slot] * self.bearing_noise * factor
        out = {"rab_distance": np.full((n, k), np.inf), "rab_bearing": np.zeros((n, k)),
               "rab_data": np.zeros((n, k, self.payload), np.uint8)}  # fmt: skip
        out["rab_distance"][row, slot] = distance
        out["rab_bearing"][row, slot] = (bearing + math.pi) % (2 * math.pi) - math.pi
        out["rab_data"][row, slot] = r.state.rab_sent[other, : self.payload]
        out["rab_count"] = np.bincount(row, minlength=n).astype(np.int64)
        return out

    def heard(self, robots: np.ndarray, state) -> tuple[np.ndarray, ...]:
        """(row in `robots`, neighbour's global id, distance, bearing from the heading) of every pair
        within range (and in sight), sorted by row, then distance, then id."""
        row, other = _pairs(robots, state, self.range)
        pose = state.pose
        d = pose[other, :2] - pose[robots[row], :2]
        distance = np.hypot(d[:, 0], d[:, 1])
        near = distance <= self.range
        row, other, distance, d = row[near], other[near], distance[near], d[near]
        bearing = np.arctan2(d[:, 1], d[:, 0]) - pose[robots[row], 2]
        if self.occlusion and len(row):
            seen = state.in_sight(robots[row], other, bearing, distance)
            row, other, distance, bearing = row[seen], other[seen], distance[seen], bearing[seen]
        order = np.lexsort((other, distance, row))
        return row[order], other[order], distance[order], bearing[order]

    def readings(self) -> dict[str, tuple[tuple[int, ...], str]]:
        k = self.max_neighbours
        return {"rab_distance": ((k,), "<f8"), "rab_bearing": ((k,), "<f8"), "rab_data": ((k, self.payload), "|u1"),
                "rab_count": ((), "<i8")}  # fmt: skip

    @classmethod
    def tells(cls, spec: Sensor | None, model) -> dict[str, Any]:
        assert spec is None or isinstance(spec, RangeAndBearing)
        return {"rab_range": None if spec is None else spec.range,
                "rab_max_neighbours": None if spec is None else spec.max_neighbours,
                "rab_payload": None if spec is None else spec.payload}  # fmt: skip


def _pairs(robots: np.ndarray, state, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """(row in `robots`, other robot's global id) of the pairs that may be within `reach`: both
    robots in the world with an agent and the sensor (a robot without it sends nothing), not the
    same.  Every pair in a small world; a k-d tree's candidates (a hair beyond `reach`: the caller
    cuts at the exact distance) in a large one."""
    live = state.in_world & state.present & (state.rab_size > 0)
    hearing = np.flatnonzero(live[robots])
    others = np.flatnonzero(live)
    if len(others) <= DENSE_UP_TO:
        row, other = np.repeat(hearing, len(others)), np.tile(others, len(hearing))
    else:
        from scipy.spatial import cKDTree  # the world's side only: an agent process reads specs without scipy

        xy = state.pose[:, :2]
        found = cKDTree(xy[robots[hearing]]).sparse_distance_matrix(
            cKDTree(xy[others]), reach * (1 + 1e-9) + 1e-12, output_type="ndarray"
        )
        row, other = hearing[found["i"]], others[found["j"]]
    apart = robots[row] != other
    return row[apart], other[apart]


def _slots(row: np.ndarray) -> np.ndarray:
    """Each pair's place among its row's (rows sorted): 0 for the nearest."""
    if not len(row):
        return np.zeros(0, np.int64)
    first = np.searchsorted(row, row, side="left")
    return np.arange(len(row)) - first


SENSOR = RangeAndBearing
