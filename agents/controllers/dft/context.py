"""Obstacles a dft robot senses and shares: the context key space.

With `obstacles = "sensed"` a robot turns each proximity reading into a point
(its position sensor, its compass, the sensor's bearing and the range the
reading means on the e-puck's response curve).  A point that is not on its
map (farther than `margin` from every wall it was given) marks a disc of
`mark_radius` as an obstacle, with the tick it was seen; a sensor that sees
nothing within its range clears the marks along its ray; a mark not seen
again for `memory` ticks is forgotten; a robot's own body clears the marks
under it (robots are obstacles to each other: one that was seen moves on).
What a robot marks and clears each tick it publishes on
swarm/<run>/context/<agent>; every robot merges what the others wrote, so
one that meets an obstacle first tells the rest.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from world_server.arena.face.sensors.ir import IR_DISTANCE, IR_VALUE

NEVER = -1
MAX_CELLS = 4096  # most cells one publication may name


def grown(mask: np.ndarray, by: int) -> np.ndarray:
    """`mask` dilated by a (2 by + 1)-cell square, nothing beyond the edge: scipy.ndimage's
    binary_dilation with that square, one axis at a time (a square is separable), in numpy so an
    agent process need not import scipy (the agent process's 80 MB budget)."""
    out = mask
    for axis in range(mask.ndim):
        wide = out.copy()
        n = mask.shape[axis]
        for d in range(1, min(by, n - 1) + 1):
            ahead = [slice(None)] * mask.ndim
            behind = [slice(None)] * mask.ndim
            ahead[axis], behind[axis] = slice(d, None), slice(None, n - d)
            wide[tuple(ahead)] |= out[tuple(behind)]
            wide[tuple(behind)] |= out[tuple(ahead)]
        out = wide
    return out


class SensedContext:
    def __init__(self, walls: np.ndarray, cell: float, radius: float, bearings, mounts, margin: float,
                 mark_radius: float, memory: int, min_reading: float):  # fmt: skip
        """`mounts`: each sensor's distance from the robot's centre, where its range is measured from."""
        self.shape, self.cell = walls.shape, cell
        self.bearings = np.asarray(bearings, np.float64)
        self.mounts = np.asarray(mounts, np.float64)
        self.memory, self.min_reading = memory, min_reading
        grow = max(1, round(margin / cell))
        self.known = grown(np.asarray(walls, bool), grow)
        r = max(1, round(mark_radius / cell))
        dj, di = np.mgrid[-r : r + 1, -r : r + 1]
        inside = dj**2 + di**2 <= r * r
        self.disc = np.column_stack([dj[inside], di[inside]])
        own = radius + mark_radius  # marks others put on this robot's rim reach this far from its centre
        b = math.ceil(own / cell)
        dj, di = np.mgrid[-b : b + 1, -b : b + 1]
        inside = (dj * cell) ** 2 + (di * cell) ** 2 <= own**2
        self.body = np.column_stack([dj[inside], di[inside]])
        self.seen = np.full(self.shape, NEVER, np.int64)  # tick each cell was last seen blocked
        self.marked: list[tuple[int, int]] = []
        self.cleared: list[tuple[int, int]] = []

    def _cells(self, points: np.ndarray, offsets: np.ndarray) -> np.ndarray:
        """Unique in-field cells (j, i) of discs of `offsets` round points (x, y)."""
        if not len(points):
            return np.zeros((0, 2), np.int64)
        centre = np.column_stack([np.floor(points[:, 1] / self.cell), np.floor(points[:, 0] / self.cell)])
        cells = (centre[:, None, :] + offsets[None, :, :]).reshape(-1, 2).astype(np.int64)
        keep = (cells[:, 0] >= 0) & (cells[:, 0] < self.shape[0]) & (cells[:, 1] >= 0) & (cells[:, 1] < self.shape[1])
        return np.unique(cells[keep], axis=0)

    def sense(self, position, heading: float, ir: np.ndarray, tick: int) -> None:
        """This tick's readings: mark what is not on the map, clear what the free rays cross."""
        x, y = float(position[0]), float(position[1])
        ir = np.asarray(ir, np.float64)
        angle = heading + self.bearings
        hit = ir >= self.min_reading
        marked = cleared = np.zeros((0, 2), np.int64)
        if hit.any():
            rng = self.mounts[hit] + np.interp(ir[hit], IR_VALUE[::-1], IR_DISTANCE[::-1])
            points = np.column_stack([x + rng * np.cos(angle[hit]), y + rng * np.sin(angle[hit])])
            cj = np.clip(np.floor(points[:, 1] / self.cell).astype(int), 0, self.shape[0] - 1)
            ci = np.clip(np.floor(points[:, 0] / self.cell).astype(int), 0, self.shape[1] - 1)
            unknown = ~self.known[cj, ci]
            marked = self._cells(points[unknown], self.disc)
        free = ir <= 0
        if free.any():
            steps = self.mounts[free][:, None] + np.arange(0.0, IR_DISTANCE[-1] + 1e-9, self.cell)[None, :]
            a = angle[free][:, None]
            points = np.column_stack([(x + steps * np.cos(a)).ravel(), (y + steps * np.sin(a)).ravel()])
            cleared = self._cells(points, np.zeros((1, 2), np.int64))
        if len(cleared):  # only what was marked is news to the others
            cleared = cleared[self.seen[cleared[:, 0], cleared[:, 1]] != NEVER]
        body = self._cells(np.array([[x, y]]), self.body)
        self._apply(marked, np.concatenate([cleared, body]), tick)
        self.marked = [tuple(c) for c in marked.tolist()]
        self.cleared = [tuple(c) for c in cleared.tolist()]

    def _apply(self, marked: np.ndarray, cleared: np.ndarray, tick: int) -> None:
        if len(cleared):
            self.seen[cleared[:, 0], cleared[:, 1]] = NEVER
        if len(marked):
            self.seen[marked[:, 0], marked[:, 1]] = np.maximum(self.seen[marked[:, 0], marked[:, 1]], tick)

    def blocked(self, tick: int) -> np.ndarray:
        """Cells marked within the last `memory` ticks."""
        return (self.seen != NEVER) & (self.seen > tick - self.memory)

    # ------------------------------------------------------------ sharing

    def publish(self, tick: int) -> dict[str, Any] | None:
        if not self.marked and not self.cleared:
            return None
        flat = {k: [v for c in getattr(self, k) for v in c] for k in ("marked", "cleared")}
        return {"tick": tick, **flat}

    def receive(self, data: Any) -> None:
        """Another robot's publication (ValueError if malformed: nothing of it is applied)."""
        if not isinstance(data, dict) or not isinstance(data.get("tick"), int):
            raise ValueError("context: expected {tick, marked, cleared}")
        cells = []
        for key in ("marked", "cleared"):
            flat = data.get(key)
            if not isinstance(flat, list) or len(flat) % 2 or len(flat) > 2 * MAX_CELLS:
                raise ValueError(f"context: {key} must be a list of j, i pairs")
            if not all(isinstance(v, int) for v in flat):
                raise ValueError(f"context: {key} holds a non-integer")
            arr = np.array(flat, np.int64).reshape(-1, 2)
            if len(arr) and ((arr < 0).any() or (arr >= np.array(self.shape)).any()):
                raise ValueError(f"context: {key} names a cell outside the field")
            cells.append(arr)
        self._apply(cells[0], cells[1], int(data["tick"]))

    def snapshot(self) -> dict[str, Any]:
        return {"seen": self.seen, "marked": self.marked, "cleared": self.cleared}

    def checked(self, state: dict[str, Any]) -> tuple[np.ndarray, list[tuple], list[tuple]]:
        """(seen, marked, cleared) from a state, changing nothing: raises on anything that does not fit."""
        return (np.asarray(state["seen"], np.int64).reshape(self.shape), [tuple(c) for c in state["marked"]],
                [tuple(c) for c in state["cleared"]])  # fmt: skip

    def put(self, parts: tuple[np.ndarray, list[tuple], list[tuple]]) -> None:
        self.seen[...], self.marked, self.cleared = parts
