"""One physics space of the arena: the robots of one strip of the floor.

A scenario may cut its floor into strips along x (`physics_strips`), each
with a pymunk space of its own, so that the strips' steps run side by side on
the world's threads (pymunk's step lets go of the interpreter lock).  A strip
owns the robots whose centre lies in it.  The robots of other strips within
`halo` of its edges (close enough to touch one of its own within a control
period) are in its space too, as ghosts: bodies like any other, driven as
their owners drive them, so that a contact across an edge shares its push
between the two robots as one space would.  Before every substep each ghost
is put where its owner's space left it; what a ghost's own step makes of it
is dropped.  Every strip holds every wall and obstacle.  With one strip
there are no ghosts and the space is the whole world's.

Bodies are named by their robot (`robot_of_row`); every shape has the stable
key that saved contacts use (walls, then robots, then scheduled obstacles,
world_server.arena.contacts).
"""

from __future__ import annotations

import numpy as np

WALL_TYPE, ROBOT_TYPE = 1, 2


def owners(x: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """The strip of each robot's centre x; `edges` are the strips' bounds (strips + 1), the outer ones
    open (a robot outside the floor, such as a parked one, belongs to the nearest strip)."""
    return np.searchsorted(edges[1:-1], x, side="right")


class Strip:
    def __init__(self, pm, batch, index: int, lo: float, hi: float, rects: np.ndarray, segments: np.ndarray,
                 robots: int):  # fmt: skip
        self._pm, self._batch = pm, batch
        self.index, self.lo, self.hi = index, lo, hi
        self.space = pm.Space()
        self.space.collision_slop = 0.0005
        self.walls_body = self.space.static_body  # pymunk adds it on first use: body rows end with it, walls or none
        self.keyed: dict[int, object] = {}
        for rect in rects:
            self.add_static(box=rect)
        for seg in segments:
            self.add_static(segment=seg)
        self.walls = len(self.keyed)
        self.bodies: dict[int, object] = {}  # robot -> its body here (its own, or its ghost)
        self.discs: dict[int, object] = {}
        self.body_id = np.zeros(robots, np.int64)  # each robot's body's id here, 0 where it has none
        self.obstacles: dict[int, list] = {}
        self._arbiters, self._get = batch.Buffer(), batch.Buffer()
        # the batches' fields, combined once (an enum's | costs as much as a small read)
        self._state_fields = batch.BodyFields.POSITION | batch.BodyFields.VELOCITY
        arbiter = batch.ArbiterFields
        self._begun_fields = arbiter.BODY_A_ID | arbiter.BODY_B_ID | arbiter.IS_FIRST_CONTACT
        self.reindex(np.zeros(robots, np.int64))

    # ------------------------------------------------------------- shapes

    def _key(self, shape, key: int) -> None:
        shape.key = key
        self.keyed[key] = shape

    def add_static(self, box=None, segment=None, key: int | None = None) -> list:
        pm = self._pm
        if box is not None:
            x0, y0, x1, y1 = (float(v) for v in box)
            shape = pm.Poly(self.walls_body, [(x0, y0), (x1, y0), (x1, y1), (x0, y1)])
        else:
            x0, y0, x1, y1 = (float(v) for v in segment)
            shape = pm.Segment(self.walls_body, (x0, y0), (x1, y1), 0.002)
        shape.friction = 0.0
        shape.collision_type = WALL_TYPE
        self.space.add(shape)
        self._key(shape, len(self.keyed) if key is None else key)
        return [shape]

    def set_obstacle(self, key: int, rect: np.ndarray | None, first_key: int) -> None:
        if rect is None:
            shapes = self.obstacles.pop(key, [])
            if shapes:
                self.space.remove(*shapes)
                del self.keyed[shapes[0].key]
        elif key not in self.obstacles:
            self.obstacles[key] = self.add_static(box=rect, key=first_key + key)

    # ------------------------------------------------------------- bodies

    def add_robot(self, i: int, xy, radius: float, parked: bool) -> None:
        pm = self._pm
        body = pm.Body(1.0, float("inf"))
        body.position = (float(xy[0]), float(xy[1]))
        disc = pm.Circle(body, float(radius))
        disc.friction = 0.0
        disc.collision_type = ROBOT_TYPE
        disc.robot = i
        if parked:
            disc.filter = pm.ShapeFilter(categories=0, mask=0)  # touches nothing
        self.space.add(body, disc)
        self._key(disc, self.walls + i)
        self.bodies[i], self.discs[i] = body, disc
        self.body_id[i] = body.id

    def remove_robot(self, i: int) -> None:
        disc = self.discs.pop(i)
        self.space.remove(self.bodies.pop(i), disc)
        self.body_id[i] = 0
        del self.keyed[disc.key]

    def reindex(self, owner: np.ndarray) -> None:
        """Which robot each body row is (the space's order changes as bodies come and go), which rows are
        its own robots' and which are ghosts, and the buffers of a row each.  Chipmunk visits the space's
        static body (the walls') after the robots: its row is kept last, read and written back as it is."""
        robots = np.flatnonzero(self.body_id)
        order = np.argsort(self.body_id[robots])
        self._robot_of_sorted = robots[order]
        self._sorted_ids = self.body_id[self._robot_of_sorted]
        self._get.clear()
        self._batch.get_space_bodies(self.space, self._batch.BodyFields.BODY_ID, self._get)
        rows = np.frombuffer(self._get.int_buf(), np.int64)
        if len(rows) != len(robots) + 1 or rows[-1] != self.walls_body.id:
            raise RuntimeError(f"a physics strip's space holds {len(rows)} bodies, not its {len(robots)} robots' "
                               "and its walls': a body was added outside world_server.arena.strips")  # fmt: skip
        self.robot_of_row = self._robots_of(rows[:-1])
        self.owned_row = owner[self.robot_of_row] == self.index
        self.ghost_row = np.flatnonzero(~self.owned_row)
        self.own_rows = np.flatnonzero(self.owned_row)
        self.own_robots = self.robot_of_row[self.own_rows]
        self.force = np.zeros(2 * len(robots) + 2)  # the static body's last
        self._set = self._batch.Buffer()
        self._set.set_float_buf(self.force)
        self._bodies = np.zeros((len(robots) + 1, 4))
        self.state = self._bodies[:-1]  # each robot row's position and velocity, as last read
        self._put = self._batch.Buffer()
        self._put.set_float_buf(self._bodies.ravel())
        self._owns = owner == self.index

    # ------------------------------------------------------------- stepping

    def read(self) -> np.ndarray:
        """Every body's position and velocity, by row (into `state`)."""
        self._get.clear()
        self._batch.get_space_bodies(self.space, self._state_fields, self._get)
        self._bodies[...] = np.frombuffer(self._get.float_buf(), dtype=np.float64).reshape(-1, 4)
        return self.state

    def follow(self, state: np.ndarray) -> None:
        """Each ghost where its owner is (`state`: every robot's position and velocity).  Every body is
        set in one batch; the others (and the walls' static body) get back what they hold."""
        if len(self.ghost_row):
            self.state[self.ghost_row] = state[self.robot_of_row[self.ghost_row]]
            self._batch.set_space_bodies(self.space, self._state_fields, self._put)

    def push(self) -> None:
        """The forces in `force` (row order) onto the bodies."""
        self._batch.set_space_bodies(self.space, self._batch.BodyFields.FORCE, self._set)

    def begun(self) -> np.ndarray:
        """The contacts that began in the last step, as the owned robots they began for (a robot pair
        counts for both).  Chipmunk marks a contact's first step;
        reading them in one batch costs what a `begin` callback into Python costs for a handful."""
        self._arbiters.clear()
        self._batch.get_space_arbiters(self.space, self._begun_fields, self._arbiters)
        pairs = np.frombuffer(self._arbiters.int_buf(), np.int64).reshape(-1, 3)
        robots = self._robots_of(pairs[pairs[:, 2] != 0, :2].ravel())
        return robots[self._owns[robots]] if len(self.ghost_row) else robots  # ghosts count in their own strip

    def _robots_of(self, body_ids: np.ndarray) -> np.ndarray:
        """The robots of these bodies, in their order (the walls' static body left out)."""
        n = len(self._sorted_ids)
        if len(body_ids) == 0 or n == 0:
            return np.zeros(0, np.int64)
        at = np.minimum(np.searchsorted(self._sorted_ids, body_ids), n - 1)
        return self._robot_of_sorted[at[self._sorted_ids[at] == body_ids]]


__all__ = ["ROBOT_TYPE", "WALL_TYPE", "Strip", "owners"]
