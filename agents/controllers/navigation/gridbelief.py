"""Markov localization over a finished topological map's nodes, carried on a
grid of the map's odometric frame.

`TopoMap.localize` predicts with the links alone: a robot leaves a node at a
constant rate per observation and goes along a link whose direction agrees
with its motion.  That rate knows nothing of where in a node the robot is, so
in a corridor cut into stretches that look alike the belief moves on too
early or too late.  Every node also remembers where (odometry) each of its
observations was taken; here the belief lives on cells of that frame, each
cell standing for the node of the nearest observation within `reach`, and
moves with the odometry as a histogram filter does.  The belief over nodes is
the sum over each node's cells, and the correction is the map's own (each
node weighed by P(match) ** sharpness, plus a floor); cells off the map are
cells too, weighed as a place that matches about as well as a look-alike room, so the belief can
follow the robot where the map has no node and come back with it.  It needs the map to be
finished (the cells are laid once) and its frame to hold together, which a
compass-aligned odometry does over a tour; while mapping, the link model
stays in charge.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from agents.controllers.navigation.params import GridParams
from agents.controllers.navigation.topomap import TopoMap


class GridBelief:
    """The belief of a robot localizing on a finished map (see the module's docstring)."""

    def __init__(self, topomap: TopoMap, params: GridParams | None = None):
        self.map = topomap
        self.p = params or GridParams()
        points, owners = [], []
        for j, node in enumerate(topomap.nodes):
            if j not in topomap.folded:
                points += [(x, y) for x, y, _ in node.seen_at]
                owners += [j] * len(node.seen_at)
        if not points:
            raise ValueError("a grid belief needs a map whose nodes remember where they were observed (seen_at)")
        xy = np.array(points, np.float64)
        margin = self.p.reach + self.p.cell
        self.origin = xy.min(axis=0) - margin
        self.shape = tuple(math.ceil(s) for s in (xy.max(axis=0) + margin - self.origin) / self.p.cell)
        node_of = _nearest_owner(self.origin, self.shape, self.p.cell, xy, np.array(owners), self.p.reach)
        self.mapped = node_of >= 0
        self.cells = np.where(self.mapped, node_of, 0)  # node index per cell (0 where off the map: weighed apart)
        self.mapped_nodes = node_of[self.mapped]  # the node of each mapped cell, in the order belief[mapped] reads
        self.uniform = self.mapped / self.mapped.sum()  # the same belief on every mapped cell, none off the map
        self.belief = self.uniform.copy()  # global localization: anywhere on the map
        self.residual = np.zeros(2)  # motion smaller than a cell, not applied yet

    def nodes(self) -> np.ndarray:
        """The belief over the map's nodes (the mass on cells off the map left out, then normalised)."""
        b = np.bincount(self.mapped_nodes, weights=self.belief[self.mapped], minlength=len(self.map.nodes))
        total = b.sum()
        return b / total if total > 0 else np.full(len(b), 1.0 / len(b))

    def predict(self, displacement: np.ndarray) -> None:
        """Move the belief by `displacement` (odometric frame) and blur it by the slip of that much travel."""
        moved = float(np.hypot(*displacement))
        total = self.residual + np.asarray(displacement, np.float64) / self.p.cell
        shift = np.round(total).astype(np.int64)
        self.residual = total - shift
        b = _shifted(self.belief, int(shift[0]), int(shift[1]))
        a = min(0.25, 0.5 * self.p.slip**2 * moved / self.p.cell**2)  # a 3-tap kernel [a, 1-2a, a] has variance 2a
        if a > 0:  # along x, then along y
            b = (1 - 2 * a) * b + a * (_shifted(b, 1, 0) + _shifted(b, -1, 0))
            b = (1 - 2 * a) * b + a * (_shifted(b, 0, 1) + _shifted(b, 0, -1))
        self.belief = b

    def correct(self, likelihood: np.ndarray) -> None:
        """Weigh each cell by its node's likelihood (plus the map's floor), as `TopoMap.correct` weighs nodes."""
        p = self.map.params
        weight = likelihood if self.p.sharpness == 1.0 else likelihood**self.p.sharpness
        w = np.where(self.mapped, weight[self.cells] + p.floor, self.p.off_map)
        b = self.belief * w
        total = b.sum()
        b = b / total if total > 0 else self.uniform
        self.belief = (1 - self.p.spread) * b + self.p.spread * self.uniform

    def update(self, likelihood: np.ndarray, displacement: np.ndarray) -> np.ndarray:
        """Predict with the odometry since the last observation, correct with this one's
        likelihood at every node; returns the belief over nodes."""
        self.predict(displacement)
        self.correct(likelihood)
        return self.nodes()

    def to_data(self) -> dict[str, Any]:
        return {"belief": self.belief.ravel().tolist(), "residual": self.residual.tolist()}

    def restore(self, data: dict[str, Any]) -> None:
        belief = np.array(data["belief"], np.float64)
        if belief.size != self.belief.size:
            raise ValueError(f"grid belief: {belief.size} cells saved, the map lays {self.belief.size}")
        self.belief = belief.reshape(self.shape)
        self.residual = np.array(data["residual"], np.float64)


def _shifted(b: np.ndarray, dx: int, dy: int) -> np.ndarray:
    """`b` moved by (dx, dy) cells; what leaves the grid is lost, what enters is zero."""
    out = np.zeros_like(b)
    nx, ny = b.shape
    if abs(dx) >= nx or abs(dy) >= ny:
        return out
    out[max(dx, 0) : nx + min(dx, 0), max(dy, 0) : ny + min(dy, 0)] = b[
        max(-dx, 0) : nx + min(-dx, 0), max(-dy, 0) : ny + min(-dy, 0)
    ]
    return out


def _nearest_owner(origin: np.ndarray, shape: tuple[int, int], cell: float, points: np.ndarray, owners: np.ndarray,
                   reach: float) -> np.ndarray:  # fmt: skip
    """Per cell, the owner of the nearest point within `reach` of its centre (-1 if none)."""
    gx = origin[0] + (np.arange(shape[0]) + 0.5) * cell
    gy = origin[1] + (np.arange(shape[1]) + 0.5) * cell
    out = np.full(shape, -1, np.int64)
    for i, x in enumerate(gx):  # one column of cells against every point: no cells x points matrix in memory
        near = np.abs(points[:, 0] - x) <= reach
        if not near.any():
            continue
        d = np.hypot(points[near, 0][None, :] - x, points[near, 1][None, :] - gy[:, None])
        k = d.argmin(axis=1)
        hit = d[np.arange(len(gy)), k] <= reach
        out[i, hit] = owners[near][k[hit]]
    return out
