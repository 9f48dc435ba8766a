"""Robot bodies: where each agent physically is, and whether its move succeeds.

`ideal` (the paper's semantics, the default): a body is the point at the centre
of its cell and every legal move succeeds at once; nothing is simulated.

`physical`: every body is a pymunk disc of the scenario's diameter on a plane
where each obstacle cell is a solid square and the grid has walls around it.
Within one tick every body drives at up to `speed` towards the centre of the
cell its controller chose (its own cell when it stays) and is pushed by the
others and by walls, so robots collide and queue in corridors and at the base.
The tick ends when every body is within `arrive` of its target, or after
`timeout` simulated seconds.  A move counts only for a body that arrived; a
body that did not keeps its logical cell, stays where it was pushed, and drives
on from there next tick (round walls along the grid when it was pushed more than
a cell away: world_server/grid/steering.py).  The base is a nest (see `_nest`).  A blocked body
also steps to its right (keep-right traffic rule), so robots that fit side by
side pass each other.  Time spent blocked is the simulated time a body with an
unreached target moved at less than half of its commanded speed.  Bodies
stop at the end of every tick (stop-and-go robots: no momentum across decisions).

Coordinates are in cells: x = column + 0.5, y = row + 0.5 is a cell's centre.
All per-body work in the physics loop is numpy over pymunk's batch API (one
call per physics step, not one per body).
"""

from __future__ import annotations

import numpy as np

from world_server.grid.face.layout import A_MOVE, DIR_DC, DIR_DR, N_DIRS, STAY
from world_server.grid.params import PhysicsParams
from world_server.grid.steering import waypoints

_GOLDEN_ANGLE = np.pi * (3.0 - np.sqrt(5.0))
# Collision categories: walls; bodies; bodies in the nest (the base cell), which
# touch walls only; removed bodies touch nothing.
_WALL, _BODY, _NEST = 0b001, 0b010, 0b100
SIDESTEP = 0.5  # a blocked body's sideways speed, as a share of its commanded speed


class Bodies:
    def __init__(self, params: PhysicsParams, obstacles: np.ndarray, n: int, base: tuple[int, int]):
        self.params = params
        self.physical = params.mode == "physical"
        self.obstacles = np.asarray(obstacles, dtype=bool)
        self.base = base
        self.sim_seconds = 0.0  # simulated time of the run (physical)
        self.blocked_seconds = 0.0  # summed over bodies
        self.blocked_moves = 0  # moves that did not arrive in time
        self.xy = np.tile(cell_centres(np.array([base])), (n, 1))
        if self.physical:
            # Deterministic start: a sunflower spiral around the base centre (no two
            # discs on the same point); pymunk pushes the overlapping ones apart.
            k = np.arange(n, dtype=np.float64)
            radius = 0.3 * np.sqrt((k + 0.5) / max(n, 1))
            self.xy += np.column_stack([radius * np.cos(k * _GOLDEN_ANGLE), radius * np.sin(k * _GOLDEN_ANGLE)])
            self._build_space(n)

    # ----------------------------------------------------------------- pymunk

    def _build_space(self, n: int) -> None:
        import pymunk
        import pymunk.batch

        self._batch = pymunk.batch
        space = pymunk.Space()
        space.collision_slop = 0.005
        static = space.static_body
        walls = [pymunk.Poly(static, [(c, r), (c + 1, r), (c + 1, r + 1), (c, r + 1)])
                 for r, c in zip(*np.nonzero(self.obstacles), strict=True)]  # fmt: skip
        h, w = self.obstacles.shape
        walls += [pymunk.Segment(static, a, b, 0.0) for a, b in
                  (((0, 0), (w, 0)), ((w, 0), (w, h)), ((w, h), (0, h)), ((0, h), (0, 0)))]  # fmt: skip
        for shape in walls:
            shape.friction = 0.0
            shape.filter = pymunk.ShapeFilter(categories=_WALL)
        space.add(*walls)
        self._filters = {
            "solid": pymunk.ShapeFilter(categories=_BODY),
            "nest": pymunk.ShapeFilter(categories=_NEST, mask=_WALL),
            "removed": pymunk.ShapeFilter(categories=0, mask=0),
        }
        self._shapes = []
        for x, y in self.xy:
            body = pymunk.Body(1.0, float("inf"))  # discs do not spin
            body.position = (float(x), float(y))
            disc = pymunk.Circle(body, self.params.diameter / 2)
            disc.friction = 0.0
            disc.filter = self._filters["nest"]  # everyone starts on the base
            space.add(body, disc)
            self._shapes.append(disc)
        self._kind = np.full(n, "nest", dtype="<U7")  # nest | solid | removed, per body
        self.space = space
        # The batch API walks dynamic bodies in insertion order, then the static body.
        self._force = np.zeros(2 * n + 2, dtype=np.float64)
        self._set = pymunk.batch.Buffer()
        self._set.set_float_buf(self._force)
        self._get = pymunk.batch.Buffer()

    def _state(self) -> tuple[np.ndarray, np.ndarray]:
        """Positions and velocities of all bodies, (n, 2) each."""
        self._get.clear()
        fields = self._batch.BodyFields
        self._batch.get_space_bodies(self.space, fields.POSITION | fields.VELOCITY, self._get)
        n = len(self.xy)
        state = np.frombuffer(self._get.float_buf(), dtype=np.float64)[: 4 * n].reshape(n, 4)
        return state[:, :2].copy(), state[:, 2:].copy()

    def _drive(self, velocity: np.ndarray, wanted: np.ndarray) -> None:
        """Push every body towards its wanted velocity within one step.  A force,
        not a set velocity: the contact solver's corrections must survive into
        the next step, or bodies would pass through each other."""
        self._force[: wanted.size] = ((wanted - velocity) / self.params.dt).ravel()  # mass 1
        self._batch.set_space_bodies(self.space, self._batch.BodyFields.FORCE, self._set)

    # ------------------------------------------------------------------- tick

    def move(self, pos: np.ndarray, acts: np.ndarray) -> np.ndarray:
        """Drive every body towards its chosen cell; turn the moves of bodies
        that did not arrive into STAY (in `acts`), so the grid rules see only
        moves that happened, and return 1 for those bodies (their robots sense
        it next tick).  Moves into walls are left for the grid to reject."""
        if not self.physical:
            return np.zeros(len(pos), dtype=np.int64)
        p = self.params
        target = pos.copy()
        d = acts[:, A_MOVE]
        moving = (d >= 0) & (d < N_DIRS)
        dirs = np.where(moving, d, 0)
        cand = pos + np.column_stack([DIR_DR[dirs], DIR_DC[dirs]])
        h, w = self.obstacles.shape
        inside = (cand[:, 0] >= 0) & (cand[:, 0] < h) & (cand[:, 1] >= 0) & (cand[:, 1] < w)
        free = np.zeros(len(pos), dtype=bool)
        free[inside] = ~self.obstacles[cand[inside, 0], cand[inside, 1]]
        legal = moving & free
        target[legal] = cand[legal]
        in_nest = self._nest(pos)
        goal = cell_centres(target)
        xy, vel = self._state()
        blocked = np.zeros(len(xy), dtype=bool)
        drive_to = np.empty_like(goal)
        t = 0.0
        for _ in range(round(p.timeout / p.dt)):
            away = np.hypot(*(goal - xy).T) > p.arrive
            if not away.any():
                break
            waypoints(xy, target, self.obstacles, drive_to)  # the goal, or the way round a wall
            delta = drive_to - xy
            dist = np.hypot(delta[:, 0], delta[:, 1])
            command = np.minimum(p.speed, dist / p.dt)
            heading = delta / np.maximum(dist, 1e-12)[:, None]
            # Keep right: a blocked body also sidesteps to its right, so two robots
            # meeting head-on in a corridor slide past each other (if they fit).
            right = np.column_stack([-heading[:, 1], heading[:, 0]]) * (SIDESTEP * blocked)[:, None]
            self._drive(vel, (heading + right) * command[:, None])
            self.space.step(p.dt)
            t += p.dt
            xy, vel = self._state()
            achieved = np.hypot(vel[:, 0], vel[:, 1])  # after the contact solver
            blocked = away & (achieved < 0.5 * command)
            self.blocked_seconds += p.dt * int(blocked.sum())
        self._force[:] = 0.0  # robots stop at the end of a tick: no momentum across decisions
        self._batch.set_space_bodies(self.space, self._batch.BodyFields.VELOCITY, self._set)
        self.xy = xy
        self.sim_seconds += t
        arrived = np.hypot(*(goal - xy).T) <= p.arrive
        self._admit_leavers(in_nest & legal & arrived, arrived)
        failed = legal & ~arrived
        self.blocked_moves += int(failed.sum())
        acts[failed, A_MOVE] = STAY
        return failed.astype(np.int64)

    def _nest(self, pos: np.ndarray) -> np.ndarray:
        """Bodies on the base collide with walls only; returns who is in the nest.
        All agents start on the base, as in the paper, and no number of discs
        fits one cell: the base is a nest, and robots pass through each other
        in it."""
        nest = (pos[:, 0] == self.base[0]) & (pos[:, 1] == self.base[1])
        for a in np.flatnonzero((nest != (self._kind == "nest")) & (self._kind != "removed")):
            self._set_kind(int(a), "nest" if nest[a] else "solid")
        return nest

    def _admit_leavers(self, leavers: np.ndarray, arrived: np.ndarray) -> None:
        """A body leaving the nest passed through the others in it; it is out
        only if it does not overlap a solid body where it stopped.  Leavers are
        admitted in agent-id order (each admitted one is solid for the next), so
        robots leave one after another instead of spilling out as a heap."""
        solid = self._kind == "solid"
        near = 0.9 * self.params.diameter  # contacts are slightly soft
        for a in np.flatnonzero(leavers):
            if solid.any() and (np.hypot(*(self.xy[solid] - self.xy[a]).T) < near).any():
                arrived[a] = False
            else:
                solid[a] = True

    def _set_kind(self, agent: int, kind: str) -> None:
        self._kind[agent] = kind
        self._shapes[agent].filter = self._filters[kind]

    # ------------------------------------------------------------- membership

    def place(self, xy: np.ndarray) -> None:
        """Put the bodies at `xy` (a resumed run's saved positions)."""
        self.xy = np.array(xy, dtype=np.float64).reshape(-1, 2)
        if self.physical:
            for shape, (x, y) in zip(self._shapes, self.xy, strict=True):
                shape.body.position = (float(x), float(y))
                shape.body.velocity = (0.0, 0.0)

    def reset(self, agent: int) -> None:
        """A fresh body in the nest (a newcomer's); it collides again once it leaves."""
        self._put(agent, "nest")

    def remove(self, agent: int) -> None:
        """A lost robot leaves the plane: parked at the base, colliding with nothing."""
        self._put(agent, "removed")

    def _put(self, agent: int, kind: str) -> None:
        """Back to the base centre, at rest, as `kind` (nest: a newcomer; removed: lost)."""
        xy = cell_centres(np.array([self.base]))[0]
        self.xy[agent] = xy
        if self.physical:
            shape = self._shapes[agent]
            shape.body.position = (float(xy[0]), float(xy[1]))
            shape.body.velocity = (0.0, 0.0)
            self._set_kind(agent, kind)

    def positions(self, pos: np.ndarray) -> np.ndarray:
        """Each body's (x, y) in cells: the cell centre when ideal."""
        return self.xy.copy() if self.physical else cell_centres(pos)

    def summary(self, agents: int) -> dict:
        if not self.physical:
            return {"physics": "ideal"}
        total = self.sim_seconds * max(agents, 1)
        return {
            "physics": "physical",
            "body_diameter": self.params.diameter,
            "sim_seconds": round(self.sim_seconds, 3),
            "blocked_seconds": round(self.blocked_seconds, 3),
            "blocked_share": round(self.blocked_seconds / total, 4) if total else 0.0,
            "blocked_moves": self.blocked_moves,
        }


def cell_centres(cells: np.ndarray) -> np.ndarray:
    """(row, col) cells, shape (..., 2), to (x, y) centres."""
    return np.asarray(cells, dtype=np.float64)[..., ::-1] + 0.5
