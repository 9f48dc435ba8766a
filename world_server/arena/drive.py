"""Differential-drive robot bodies on pymunk: discs driven by wheel speeds.

Per control period the world hands every robot its two wheel speeds (m/s,
already validated and clamped to the model's limits).  They give a forward
speed v = (l + r) / 2 and a turn rate w = (r - l) / axle.  Over the period's
fixed substeps each disc is pushed (a force, so contact corrections survive
into the next substep) towards v along its heading, and the heading turns by
w * dt.  Discs do not spin from contacts (infinite moment): the heading is the
robot's own, integrated here.  Walls are static boxes and segments; scheduled
obstacles are added to and removed from the space when their time comes.

Chipmunk moves bodies before it applies forces, so a robot starting from rest
lags one substep behind its command (16 ms at 4 substeps of 64 ms).
Everything is in a fixed order with fixed steps, so a run is deterministic.
A stopped (lost) robot keeps its body: it becomes an obstacle that does not
move (docs/arena.md).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from world_server.arena import contacts

WALL_TYPE, ROBOT_TYPE = 1, 2
BLOCKED_SHARE = 0.5  # moving at under half of the commanded speed counts as blocked


@njit(cache=True)
def _push(v: np.ndarray, cos: np.ndarray, sin: np.ndarray, state: np.ndarray, dt: float, force: np.ndarray) -> None:
    """The force that brings each disc's velocity (state[:, 2:]) to v along its heading in one substep,
    into `force` as [fx0, fy0, fx1, ...] (pymunk's batch layout)."""
    for i in range(v.shape[0]):
        force[2 * i] = (v[i] * cos[i] - state[i, 2]) / dt
        force[2 * i + 1] = (v[i] * sin[i] - state[i, 3]) / dt


@njit(cache=True)
def _moved(after: np.ndarray, state: np.ndarray, cos: np.ndarray, sin: np.ndarray, v: np.ndarray, w: np.ndarray,
           dt: float, distance: np.ndarray, forward: np.ndarray, blocked: np.ndarray,
           pose: np.ndarray) -> None:  # fmt: skip
    """A substep's bookkeeping from where the discs went (`after`) and were (`state`): distance travelled,
    forward progress along the heading, time blocked (under BLOCKED_SHARE of the commanded speed), and the
    pose, its heading turned by w dt.  Each in the order of operations of the numpy expressions it replaced
    (their numbers to the bit: numba's hypot and float modulo are numpy's)."""
    for i in range(v.shape[0]):
        sx, sy = after[i, 0] - state[i, 0], after[i, 1] - state[i, 1]
        d = math.hypot(sx, sy)
        distance[i] += d
        forward[i] += sx * cos[i] + sy * sin[i]
        speed = abs(v[i])
        blocked[i] += dt if (speed > 1e-9 and d < BLOCKED_SHARE * speed * dt) else 0.0
        pose[i, 0], pose[i, 1] = after[i, 0], after[i, 1]
        pose[i, 2] = (pose[i, 2] + w[i] * dt) % (2 * math.pi)


class DiffDrive:
    def __init__(self, pose: np.ndarray, radius: np.ndarray, rects: np.ndarray, segments: np.ndarray,
                 period: float, substeps: int, in_world: np.ndarray | None = None):  # fmt: skip
        import pymunk
        import pymunk.batch

        self._pymunk, self._batch = pymunk, pymunk.batch
        self.n = len(pose)
        self.pose = np.array(pose, dtype=np.float64)
        self.radius = np.asarray(radius, np.float64)
        self.period, self.substeps = float(period), int(substeps)
        self.dt = self.period / self.substeps
        self.distance = np.zeros(self.n)  # travelled, per robot
        self.collisions = np.zeros(self.n, np.int64)  # contacts begun (walls or robots)
        self.blocked_seconds = np.zeros(self.n)
        self.contact = np.zeros(self.n, np.bool_)  # touched anything in the last period
        self.motion = np.zeros((self.n, 2))  # forward distance and turn of the last period
        self.sim_seconds = 0.0
        space = pymunk.Space()
        space.collision_slop = 0.0005
        # Every shape has a stable key (walls, then robots, then scheduled obstacles): saved contacts name them.
        self._keyed: dict[int, object] = {}
        for rect in rects:
            self._add_static(space, box=rect)
        for seg in segments:
            self._add_static(space, segment=seg)
        self._walls = len(self._keyed)
        self._bodies, self._discs = [], []
        for i in range(self.n):
            body = pymunk.Body(1.0, float("inf"))
            body.position = (float(self.pose[i, 0]), float(self.pose[i, 1]))
            disc = pymunk.Circle(body, float(self.radius[i]))
            disc.friction = 0.0
            disc.collision_type = ROBOT_TYPE
            disc.robot = i
            if in_world is not None and not in_world[i]:
                disc.filter = pymunk.ShapeFilter(categories=0, mask=0)  # parked: touches nothing
            space.add(body, disc)
            self._key(disc, self._walls + i)
            self._bodies.append(body)
            self._discs.append(disc)
        self.space = space
        ids = np.array([body.id for body in self._bodies], np.int64)  # bodies' addresses: sorted, to find robots
        self._body_order = np.argsort(ids)
        self._body_ids = ids[self._body_order]
        self._arbiters = pymunk.batch.Buffer()
        self._obstacles: dict[int, list] = {}
        self._force = np.zeros(2 * self.n + 2)
        self._set = pymunk.batch.Buffer()
        self._set.set_float_buf(self._force)
        self._get = pymunk.batch.Buffer()

    def _key(self, shape, key: int) -> None:
        shape.key = key
        self._keyed[key] = shape

    def _add_static(self, space, box=None, segment=None, key: int | None = None) -> list:
        pm = self._pymunk
        if box is not None:
            x0, y0, x1, y1 = (float(v) for v in box)
            shape = pm.Poly(space.static_body, [(x0, y0), (x1, y0), (x1, y1), (x0, y1)])
        else:
            x0, y0, x1, y1 = (float(v) for v in segment)
            shape = pm.Segment(space.static_body, (x0, y0), (x1, y1), 0.002)
        shape.friction = 0.0
        shape.collision_type = WALL_TYPE
        space.add(shape)
        self._key(shape, len(self._keyed) if key is None else key)
        return [shape]

    def _count_begun(self) -> None:
        """The contacts that began in the last step, counted per robot (a robot pair counts for both).
        Chipmunk marks them first contacts; reading them in one batch costs what a `begin` callback
        into Python costs for a handful (a dense crowd begins hundreds a step)."""
        self._arbiters.clear()
        fields = self._batch.ArbiterFields
        self._batch.get_space_arbiters(self.space, fields.BODY_A_ID | fields.BODY_B_ID | fields.IS_FIRST_CONTACT,
                                       self._arbiters)  # fmt: skip
        pairs = np.frombuffer(self._arbiters.int_buf(), np.int64).reshape(-1, 3)
        bodies = pairs[pairs[:, 2] != 0, :2].ravel()
        if len(bodies) == 0 or self.n == 0:
            return
        at = np.minimum(np.searchsorted(self._body_ids, bodies), self.n - 1)
        robots = self._body_order[at[self._body_ids[at] == bodies]]
        np.add.at(self.collisions, robots, 1)
        self.contact[robots] = True

    # ---------------------------------------------------------------- obstacles

    def set_obstacle(self, key: int, rect: np.ndarray | None) -> None:
        """Put a scheduled obstacle's box in the world (rect) or take it out (None)."""
        if rect is None:
            shapes = self._obstacles.pop(key, [])
            if shapes:
                self.space.remove(*shapes)
                del self._keyed[shapes[0].key]
        elif key not in self._obstacles:
            self._obstacles[key] = self._add_static(self.space, box=rect, key=self._walls + self.n + key)

    # ------------------------------------------------------------------- motion

    def _positions(self) -> np.ndarray:
        self._get.clear()
        fields = self._batch.BodyFields
        self._batch.get_space_bodies(self.space, fields.POSITION | fields.VELOCITY, self._get)
        return np.frombuffer(self._get.float_buf(), dtype=np.float64)[: 4 * self.n].reshape(self.n, 4).copy()

    def drive(self, wheels: np.ndarray, axle: np.ndarray, moving: np.ndarray, pinned: np.ndarray | None = None) -> None:
        """One control period.  `wheels` (n, 2) left/right speeds; robots with
        moving False hold still (finished robots, refused actions); `pinned`
        robots (lost agents) do not even yield to a push: an obstacle."""
        v = np.where(moving, (wheels[:, 0] + wheels[:, 1]) / 2, 0.0)
        w = np.where(moving, (wheels[:, 1] - wheels[:, 0]) / axle, 0.0)
        self.contact[:] = False
        start = self.pose.copy()
        forward = np.zeros(self.n)
        pinned_at = {} if pinned is None else {int(i): self.pose[i, :2].copy() for i in np.flatnonzero(pinned)}
        state = self._positions()
        for _ in range(self.substeps):
            heading = self.pose[:, 2]
            cos, sin = np.cos(heading), np.sin(heading)  # numpy's (its SIMD values), once a substep
            _push(v, cos, sin, state, self.dt, self._force)
            self._batch.set_space_bodies(self.space, self._batch.BodyFields.FORCE, self._set)
            self.space.step(self.dt)
            self._count_begun()
            for i in pinned_at:
                self._bodies[i].position = (float(pinned_at[i][0]), float(pinned_at[i][1]))
                self._bodies[i].velocity = (0.0, 0.0)
            after = self._positions()
            _moved(after, state, cos, sin, v, w, self.dt, self.distance, forward, self.blocked_seconds, self.pose)
            state = after
        self.motion[:, 0] = forward
        self.motion[:, 1] = (self.pose[:, 2] - start[:, 2] + math.pi) % (2 * math.pi) - math.pi
        self.sim_seconds += self.period

    def velocities(self) -> np.ndarray:
        return self._positions()[:, 2:]

    def contacts(self) -> dict[str, np.ndarray]:
        """The space's cached contacts and clock (world_server.arena.contacts)."""
        return contacts.save(self.space, lambda shape: shape.key)

    def take_contacts(self, state: dict[str, np.ndarray]) -> None:
        """Saved contacts into this (rebuilt) space: they warm-start and are not new collisions."""
        contacts.load(self.space, state, self._keyed.__getitem__)

    def set_velocities(self, velocity: np.ndarray) -> None:
        for body, (vx, vy) in zip(self._bodies, np.asarray(velocity, np.float64).tolist(), strict=True):
            body.velocity = (vx, vy)

    def enter(self, i: int, pose: np.ndarray) -> None:
        """A parked robot comes into the world at `pose`."""
        self.place(i, pose)
        self._discs[i].filter = self._pymunk.ShapeFilter()

    def place(self, i: int, pose: np.ndarray) -> None:
        self.pose[i] = pose
        self._bodies[i].position = (float(pose[0]), float(pose[1]))
        self._bodies[i].velocity = (0.0, 0.0)
