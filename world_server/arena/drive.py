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
move (docs/arena.md).  A floor cut into strips (world_server.arena.strips)
steps each strip's space on its own thread; the bits depend on the strips,
never on the threads.
"""

from __future__ import annotations

import functools
import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from numba import njit

from world_server.arena import contacts, raycast
from world_server.arena.strips import Strip, owners

BLOCKED_SHARE = 0.5  # moving at under half of the commanded speed counts as blocked


@njit(cache=True, nogil=True)
def _push(robot_of_row: np.ndarray, v: np.ndarray, cos: np.ndarray, sin: np.ndarray, bodies: np.ndarray, dt: float,
          force: np.ndarray) -> None:  # fmt: skip
    """The force that brings each body's velocity (bodies[:, 2:], by row) to its robot's v along its heading
    in one substep, into `force` as [fx0, fy0, fx1, ...] (pymunk's batch layout)."""
    for r in range(robot_of_row.shape[0]):
        i = robot_of_row[r]
        force[2 * r] = (v[i] * cos[i] - bodies[r, 2]) / dt
        force[2 * r + 1] = (v[i] * sin[i] - bodies[r, 3]) / dt


@njit(cache=True, nogil=True)
def _moved(robots: np.ndarray, rows: np.ndarray, bodies: np.ndarray, state: np.ndarray, cos: np.ndarray,
           sin: np.ndarray, v: np.ndarray, w: np.ndarray, dt: float, distance: np.ndarray, forward: np.ndarray,
           blocked: np.ndarray, pose: np.ndarray, after: np.ndarray) -> None:  # fmt: skip
    """A substep's bookkeeping for these robots, from where their bodies went (`bodies`, their `rows`) and
    were (`state`): distance travelled, forward progress along the heading, time blocked (under
    BLOCKED_SHARE of the commanded speed), the pose, its heading turned by w dt, and `after`, where they
    are now.  Each in the order of operations of the numpy expressions it replaced (their numbers to the
    bit: numba's hypot and float modulo are numpy's).  Each robot's rows only: strips run it side by side."""
    for k in range(robots.shape[0]):
        i, r = robots[k], rows[k]
        sx, sy = bodies[r, 0] - state[i, 0], bodies[r, 1] - state[i, 1]
        d = math.hypot(sx, sy)
        distance[i] += d
        forward[i] += sx * cos[i] + sy * sin[i]
        speed = abs(v[i])
        blocked[i] += dt if (speed > 1e-9 and d < BLOCKED_SHARE * speed * dt) else 0.0
        pose[i, 0], pose[i, 1] = bodies[r, 0], bodies[r, 1]
        pose[i, 2] = (pose[i, 2] + w[i] * dt) % (2 * math.pi)
        for j in range(4):
            after[i, j] = bodies[r, j]


class DiffDrive:
    def __init__(self, pose: np.ndarray, radius: np.ndarray, rects: np.ndarray, segments: np.ndarray,
                 period: float, substeps: int, in_world: np.ndarray | None = None, strips: int = 1,
                 width: float = 0.0, halo: float = 0.0):  # fmt: skip
        """`strips` cut the floor's `width` along x; a strip's space holds the robots of the others within
        `halo` of its edges (ArenaScenario.physics_halo)."""
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
        self.parked = np.zeros(self.n, np.bool_) if in_world is None else ~np.asarray(in_world, np.bool_)
        if strips > 1 and not (width > 0 and halo > 0):
            raise ValueError(f"{strips} physics strips need the floor's width and their halo, got {width} and {halo}")
        self.edges = np.linspace(0.0, float(width), strips + 1)
        self.halo = float(halo)
        self.strips = [Strip(pymunk, pymunk.batch, k, float(self.edges[k]), float(self.edges[k + 1]), rects,
                             segments, self.n) for k in range(strips)]  # fmt: skip
        self._walls = self.strips[0].walls
        self.owner = self._owners()
        self._placed = False  # a robot was put somewhere since the last period: its strips are to be found
        for strip in self.strips:
            for i in np.flatnonzero(self._members(strip, self.owner)).tolist():
                strip.add_robot(i, self.pose[i], self.radius[i], bool(self.parked[i]))
            strip.reindex(self.owner)

    @property
    def space(self):
        """The physics space of a floor in one strip."""
        if len(self.strips) != 1:
            raise ValueError(f"the floor is in {len(self.strips)} strips, each with a space: read .strips")
        return self.strips[0].space

    # ----------------------------------------------------------------- strips

    def _owners(self) -> np.ndarray:
        if len(self.strips) == 1:
            return np.zeros(self.n, np.int64)
        return owners(self.pose[:, 0], self.edges)

    def _members(self, strip: Strip, owner: np.ndarray) -> np.ndarray:
        """The robots in a strip's space: its own, and the others within the halo of its edges."""
        if len(self.strips) == 1:
            return np.ones(self.n, np.bool_)
        x = self.pose[:, 0]
        return (owner == strip.index) | ((x >= strip.lo - self.halo) & (x < strip.hi + self.halo))

    def _repartition(self) -> None:
        """Each robot to the strip its centre is in now, each strip's ghosts to those within its halo.
        A body that comes into a space, or a ghost that becomes its robot's own body, starts where the
        robot's owner left it (a ghost holds its own last step, which is dropped)."""
        new = self._owners()
        changes = []
        for strip in self.strips:
            have, want = strip.body_id != 0, self._members(strip, new)
            switched = have & want & ((self.owner == strip.index) != (new == strip.index))
            gone, come = np.flatnonzero(have & ~want), np.flatnonzero(want & ~have)
            if len(gone) or len(come) or switched.any():
                changes.append((strip, gone, come, np.flatnonzero(switched & (new == strip.index))))
        if changes:
            state = self._positions()  # read before any space changes: each robot as its owner left it
            for strip, gone, come, taken in changes:
                for i in gone.tolist():
                    strip.remove_robot(i)
                for i in come.tolist():
                    strip.add_robot(i, state[i], self.radius[i], bool(self.parked[i]))
                    strip.bodies[i].velocity = (float(state[i, 2]), float(state[i, 3]))
                for i in taken.tolist():
                    strip.bodies[i].position = (float(state[i, 0]), float(state[i, 1]))
                    strip.bodies[i].velocity = (float(state[i, 2]), float(state[i, 3]))
                strip.reindex(new)
        self.owner = new

    def _place_placed(self) -> None:
        """Robots put somewhere since the last period (`place`) to their strips, as a period begins or
        before a snapshot: spaces rebuilt from the poses then hold the same bodies."""
        if len(self.strips) > 1 and self._placed:
            self._repartition()
        self._placed = False

    def _copies(self, i: int) -> list:
        """A robot's bodies and discs: its own and its ghosts."""
        return [(s.bodies[i], s.discs[i]) for s in self.strips if i in s.bodies]

    # ---------------------------------------------------------------- obstacles

    def set_obstacle(self, key: int, rect: np.ndarray | None) -> None:
        """Put a scheduled obstacle's box in the world (rect) or take it out (None)."""
        for strip in self.strips:
            strip.set_obstacle(key, rect, self._walls + self.n)

    # ------------------------------------------------------------------- motion

    def _positions(self) -> np.ndarray:
        """Every robot's position and velocity, read from its own strip's space."""
        out = np.empty((self.n, 4))
        for strip in self.strips:
            state = strip.read()
            out[strip.robot_of_row[strip.owned_row]] = state[strip.owned_row]
        return out

    def _substep(self, v: np.ndarray, w: np.ndarray, cos: np.ndarray, sin: np.ndarray, state: np.ndarray,
                 after: np.ndarray, forward: np.ndarray, pinned_at: dict, strip: Strip) -> np.ndarray:  # fmt: skip
        """One substep of one strip's space: its ghosts put where their owners are (`state`), its bodies
        pushed, stepped, its own robots' bookkeeping done (their rows only, so strips run side by side).
        Returns its own robots' contacts begun."""
        strip.follow(state)
        _push(strip.robot_of_row, v, cos, sin, strip.state, self.dt, strip.force)
        strip.push()
        strip.space.step(self.dt)
        begun = strip.begun()
        for i, xy in pinned_at.items():
            if i in strip.bodies:
                strip.bodies[i].position = (float(xy[0]), float(xy[1]))
                strip.bodies[i].velocity = (0.0, 0.0)
        strip.read()
        _moved(strip.own_robots, strip.own_rows, strip.state, state, cos, sin, v, w, self.dt, self.distance, forward,
               self.blocked_seconds, self.pose, after)  # fmt: skip
        return begun

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
        self._place_placed()
        state = self._positions()
        workers = min(raycast.threads(), len(self.strips))
        for _ in range(self.substeps):
            heading = self.pose[:, 2]
            cos, sin = np.cos(heading), np.sin(heading)  # numpy's (its SIMD values), once a substep
            after = np.empty((self.n, 4))
            args = (v, w, cos, sin, state, after, forward, pinned_at)
            if workers > 1:
                results = list(_pool(workers).map(functools.partial(self._substep, *args), self.strips))
            else:
                results = [self._substep(*args, strip) for strip in self.strips]
            for begun in results:
                if len(begun):  # np.add.at costs microseconds even for nothing: most substeps begin none
                    np.add.at(self.collisions, begun, 1)
                    self.contact[begun] = True
            state = after
        if len(self.strips) > 1:
            self._repartition()
        self.motion[:, 0] = forward
        self.motion[:, 1] = (self.pose[:, 2] - start[:, 2] + math.pi) % (2 * math.pi) - math.pi
        self.sim_seconds += self.period

    def velocities(self) -> np.ndarray:
        return self._positions()[:, 2:]

    def contacts(self) -> dict[str, np.ndarray]:
        """The spaces' cached contacts and clocks (world_server.arena.contacts); with several strips,
        each contact's strip (`contacts_strip`) and a clock per strip."""
        self._place_placed()
        saved = [contacts.save(s.space, lambda shape: shape.key) for s in self.strips]
        if len(saved) == 1:
            return saved[0]
        out = {k: np.concatenate([d[k] for d in saved]) for k in ("contacts_f", "contacts_i", "contacts_h")}
        out["contacts_strip"] = np.repeat(np.arange(len(saved)), [len(d["contacts_i"]) for d in saved])
        out["space_clock"] = np.stack([d["space_clock"] for d in saved])
        return out

    def take_contacts(self, state: dict[str, np.ndarray]) -> None:
        """Saved contacts into these (rebuilt) spaces: they warm-start and are not new collisions."""
        if len(self.strips) == 1:
            contacts.load(self.space, state, self.strips[0].keyed.__getitem__)
            return
        for strip in self.strips:
            mine = state["contacts_strip"] == strip.index
            part = {k: state[k][mine] for k in ("contacts_f", "contacts_i", "contacts_h")}
            contacts.load(strip.space, {**part, "space_clock": state["space_clock"][strip.index]},
                          strip.keyed.__getitem__)  # fmt: skip

    def set_velocities(self, velocity: np.ndarray) -> None:
        velocity = np.asarray(velocity, np.float64)
        for strip in self.strips:
            for i, body in strip.bodies.items():
                body.velocity = (float(velocity[i, 0]), float(velocity[i, 1]))

    def enter(self, i: int, pose: np.ndarray) -> None:
        """A parked robot comes into the world at `pose`."""
        self.place(i, pose)
        self.parked[i] = False
        for _, disc in self._copies(i):
            disc.filter = self._pymunk.ShapeFilter()

    def place(self, i: int, pose: np.ndarray) -> None:
        self.pose[i] = pose
        self._placed = True
        for body, _ in self._copies(i):
            body.position = (float(pose[0]), float(pose[1]))
            body.velocity = (0.0, 0.0)


@functools.cache
def _pool(workers: int) -> ThreadPoolExecutor:
    """The threads that step the strips' spaces side by side (pymunk's step lets go of the lock)."""
    return ThreadPoolExecutor(workers, thread_name_prefix="physics")
