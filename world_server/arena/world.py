"""The arena: a continuous world of walls, zones, scheduled obstacles and
differential-drive robots, behind the same world contract as the grid
(world_server/contract.py).

A tick is lock-step: every robot perceives the start-of-tick world (one ray
pass for all sensors of all robots), the controllers decide, and `apply`
validates every action and integrates the bodies for one control period.

The world is bodies, sensing, zones and the metabolism; what a run asks of the
robots (goals, routes, dwell, the A* optimum) is the runner's
(swarm.engines.goals), which says when a robot is finished (`finish`).
"""

from __future__ import annotations

import numpy as np

from world_server.arena import raycast
from world_server.arena.drive import DiffDrive
from world_server.arena.face.sensors.zones import ZONE_KINDS
from world_server.arena.metabolism import ACTS, Metabolism
from world_server.arena.raycast import MARK, NO_HIT, SOLID, build_disc_index, build_segment_index, grid_shape
from world_server.arena.scenario import ArenaScenario
from world_server.arena.sensors import Suite
from world_server.arena.wheels import (
    ACTION_LEN,
    ACTION_WIDTH,
    NOT_FINITE,
    OVER_LIMIT,
    REJECT_REASONS,
    UNKNOWN_ACT,
    limited,
    refusals,
)


def rect_edges(rect) -> list[tuple[float, float, float, float]]:
    x0, y0, x1, y1 = rect
    return [(x0, y0, x1, y0), (x1, y0, x1, y1), (x1, y1, x0, y1), (x0, y1, x0, y0)]


class ArenaWorld:
    """The arena's state; it keeps world_server.contract.World."""

    kind = "arena"

    def __init__(self, scenario: ArenaScenario, index_cell: float | None = None, parked: bool = False):
        """`parked`: no robot is in the world yet; each comes in with `enter`
        (the world server's agents, as they join).  Else all start now."""
        self.scenario = scenario
        self.tick = 0
        self._init_robot_models()
        self._init_geometry(index_cell)
        start = self._init_bodies(parked)
        self._init_progress(start)

    def _init_robot_models(self) -> None:
        """Each robot's body and drive limits, one array entry per robot."""
        models = self.scenario.robot_models()
        self.n = len(models)
        self.radius = np.array([m.radius for m in models])
        self.axle = np.array([m.axle for m in models])
        self.max_wheel = np.array([m.max_wheel_speed for m in models])
        self.max_speed = np.array([m.max_speed for m in models])
        self.max_turn = np.array([m.max_turn_rate for m in models])
        self.robot_rgb = np.array([m.colour for m in models], np.uint8).reshape(-1, 3)
        # what each robot broadcasts to its range-and-bearing neighbours (`broadcast`), 0 bytes without the sensor
        rab = [m.sensors.range_and_bearing for m in models]
        self.rab_size = np.array([0 if s is None else s.payload for s in rab], np.int64)
        self.rab_sent = np.zeros((self.n, int(self.rab_size.max(initial=0))), np.uint8)  # what neighbours hear
        self.rab_next = self.rab_sent.copy()  # this tick's, heard from the next tick on

    def _init_geometry(self, index_cell: float | None) -> None:
        """Wall rectangles and segments, then every obstacle's edges (switched by seg_on), and the
        ray-cast indexes over them."""
        s = self.scenario
        segs, colours, self.obstacle_segs, self.obstacle_layer = [], [], [], []
        for w in s.walls:
            edges = rect_edges(w.coords) if w.shape == "rect" else [w.coords]
            segs += edges
            colours += [w.colour] * len(edges)
        for o in s.obstacles:
            self.obstacle_segs.append(np.arange(len(segs), len(segs) + 4))
            self.obstacle_layer.append(SOLID if o.solid else MARK)
            segs += rect_edges(o.rect)
            colours += [o.colour] * 4
        self.segs = np.array(segs, np.float64).reshape(-1, 4)
        self.seg_rgb = np.array(colours, np.uint8).reshape(-1, 3)
        self.seg_on = np.full(len(self.segs), SOLID, np.uint8)  # layer bits; 0 while an obstacle is away
        self.extent = (0.0, 0.0, float(s.size[0]), float(s.size[1]))
        self.cell = index_cell or default_cell(s)
        self.nx, self.ny = grid_shape(self.extent, self.cell)
        self.s_start, self.s_items = build_segment_index(self.segs, 0.0, 0.0, self.cell, self.nx, self.ny)
        self.s_coords = np.ascontiguousarray(self.segs[self.s_items])
        self.d_start = np.zeros(self.nx * self.ny + 1, np.int64)
        self._grow_discs(4 * self.n + 16)

    def _init_bodies(self, parked: bool) -> np.ndarray:
        """Bodies and sensors.  A parked robot waits outside the arena, touching nothing.
        Returns the start poses."""
        s = self.scenario
        self.in_world = np.full(self.n, not parked)
        start = np.column_stack([-10.0 - 4 * self.radius.max() * np.arange(self.n), np.full(self.n, -10.0),
                                 np.zeros(self.n)]) if parked else s.start_poses()  # fmt: skip
        self.bodies = self._new_bodies(start)
        self.present = np.ones(self.n, np.bool_)  # False: the agent is gone, its body stays as an obstacle
        self.suites: list[Suite] = []
        first = 0
        for g in s.groups:
            self.suites.append(Suite(g.robot, np.arange(first, first + g.count), s.noise, s.seed))
            first += g.count
        self._obstacles_at(0)
        return start

    def _init_progress(self, start: np.ndarray) -> None:
        """Per-robot counters and checkpoints, the zones and the metabolism."""
        s = self.scenario
        self.finished = np.zeros(self.n, np.bool_)  # done for good (dead, or the run's goals say so): holds still
        self.path_length = np.zeros(self.n)  # ground-truth distance travelled, the summary's L_p
        self.rejected = dict.fromkeys(REJECT_REASONS, 0)
        self.start_pose = start.copy()  # where each robot came into the world
        self.checkpointed: dict[str, np.ndarray] | None = None  # the snapshot of the last checkpoint
        self.zones = np.zeros(self.n, np.int64)
        self._update_zones()
        self.metabolism = None if s.metabolism is None else Metabolism(
            self.n, s.metabolism, s.control_period,
            [(o.name, o.zone, o.centre) for o in s.obstacles if o.zone is not None])  # fmt: skip

    def _new_bodies(self, pose: np.ndarray) -> DiffDrive:
        s = self.scenario
        return DiffDrive(pose, self.radius, s.wall_rects(), s.wall_segments(), s.control_period, s.substeps,
                         self.in_world, s.physics_strips, s.size[0], s.physics_halo())  # fmt: skip

    # ------------------------------------------------------------- contract

    @property
    def pose(self) -> np.ndarray:
        return self.bodies.pose

    @property
    def motion(self) -> np.ndarray:
        return self.bodies.motion

    @property
    def contact(self) -> np.ndarray:
        return self.bodies.contact

    def perceive_all(self) -> list[dict[str, np.ndarray]]:
        return self.perceive()

    def apply_all(self, actions: np.ndarray) -> None:
        self.apply(actions)

    def perceive(self) -> list[dict[str, np.ndarray]]:
        """Every robot's perception of the start-of-tick world (one ray pass)."""
        batches = self.perceive_groups()
        out = []
        for batch in batches:
            keys = list(batch)
            n = len(batch[keys[0]]) if keys else 0
            out += [{k: batch[k][i] for k in keys} for i in range(n)]
        return out

    def perceive_groups(self) -> list[dict[str, np.ndarray]]:
        """Per group, its robots' readings batched (arrays with a robot axis)."""
        rays = [suite.rays(self.tick) for suite in self.suites]
        joined = [np.concatenate([r[k] for r in rays]) for k in range(6)] if len(rays) > 1 else list(rays[0])
        if self.in_world.all():
            ranges, what = self.cast(joined[0], joined[1], joined[2], (joined[3], joined[4]), joined[5])
        else:  # parked robots sense nothing: only the rays of robots in the world are cast
            ranges, what = joined[2].copy(), np.full(len(joined[0]), NO_HIT, np.int64)
            keep = self.in_world[joined[0]]
            if keep.any():
                ranges[keep], what[keep] = self.cast(*(part[keep] for part in joined[:3]),
                                                     (joined[3][keep], joined[4][keep]), joined[5][keep])  # fmt: skip
        rgb = self.hit_colours(what) if any(s.colours for s in self.suites) else None
        out, k = [], 0
        for suite in self.suites:
            n, per = len(suite.robots), suite.per_robot
            m = n * per
            colours = None if rgb is None else rgb[k : k + m].reshape(n, per, 3)
            out.append(suite.read(ranges[k : k + m].reshape(n, per), colours, what[k : k + m].reshape(n, per), self,
                                  self.tick))  # fmt: skip
            k += m
        return out

    def _grow_discs(self, size: int) -> None:
        self.d_items = np.zeros(size, np.int64)
        self.d_xyr = np.zeros((size, 3))

    def cast(self, robot: np.ndarray, bearing: np.ndarray, max_range: np.ndarray,
             cos_sin: tuple[np.ndarray, np.ndarray] | None = None,
             mask: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
        """One compiled pass over every ray (robot-major); robots block each
        other's rays.  `cos_sin` of the bearings may be given (suites cache
        them); `mask` says which layers each ray sees (default: all)."""
        xy = np.ascontiguousarray(self.pose[:, :2])
        while True:
            got = build_disc_index(xy, self.radius, self.in_world, 0.0, 0.0, self.cell, self.nx,
                                   self.ny, self.d_start, self.d_items, self.d_xyr)  # fmt: skip
            if got >= 0:
                break
            self._grow_discs(-got + 16)
        c, s = cos_sin if cos_sin is not None else (np.cos(bearing), np.sin(bearing))
        if mask is None:
            mask = np.full(len(robot), SOLID | MARK, np.uint8)
        ranges = np.empty(len(robot))
        what = np.empty(len(robot), np.int64)
        cast = raycast.cast_rays_parallel if raycast.parallel(len(robot), raycast.PARALLEL_RAYS) else raycast.cast_rays
        cast(self.pose, np.asarray(robot, np.int64), c, s, max_range, mask, self.s_coords, self.s_items, self.seg_on,
             self.s_start, self.d_xyr, self.d_items, self.d_start, 0.0, 0.0, self.cell, self.nx, self.ny,
             ranges, what)  # fmt: skip
        return ranges, what

    def in_sight(self, robots: np.ndarray, others: np.ndarray, bearing: np.ndarray,
                 distance: np.ndarray) -> np.ndarray:  # fmt: skip
        """Whether each robot others[k] is the first solid thing (wall, box or robot) that a ray from
        robots[k]'s centre meets at `bearing` (from its heading) within `distance` (the centres')."""
        _, what = self.cast(robots, bearing, distance, mask=np.full(len(robots), SOLID, np.uint8))
        return what == -2 - others

    def broadcast(self, sent: list[tuple[int, bytes]]) -> None:
        """What robots broadcast this tick (agent, bytes): each its range-and-bearing payload, cut or
        padded with zeros to it (nothing without the sensor).  Neighbours hear it from the next tick on,
        if the world takes the robot's action this tick (`apply`); else they hear what it sent before."""
        for agent, data in sent:
            size = int(self.rab_size[agent])
            row = np.frombuffer(bytes(data[:size]), np.uint8)
            self.rab_next[agent, :size] = 0
            self.rab_next[agent, : len(row)] = row

    def hit_colours(self, what: np.ndarray) -> np.ndarray:
        rgb = np.empty((len(what), 3), np.uint8)
        raycast.hit_colours(np.asarray(what, np.int64), self.seg_rgb, self.robot_rgb, rgb)
        return rgb

    def _refusals(self, actions: np.ndarray, robots: np.ndarray) -> np.ndarray:
        """Per row of (k, 2) wheel speeds, or (k, 3) with an act, for these
        robots: the index in REJECT_REASONS of why it cannot be acted on, or -1."""
        why = np.empty(len(actions), np.int64)
        refusals(
            np.ascontiguousarray(actions, np.float64),
            self.max_wheel,
            np.ascontiguousarray(robots, np.int64),
            len(ACTS),
            self.metabolism is not None,
            why,
        )  # no metabolism here: no act means anything
        return why

    def judge(self, agent: int, wheels: np.ndarray) -> str | None:
        """Why one robot's action (wheel speeds, and an act or not) cannot be acted on, or None."""
        wheels = np.asarray(wheels, np.float64)
        if wheels.shape not in ((ACTION_LEN,), (ACTION_WIDTH,)):
            return "wrong shape"
        k = int(self._refusals(wheels[None], np.array([agent]))[0])
        return None if k < 0 else REJECT_REASONS[k]

    def validate(self, actions: np.ndarray) -> np.ndarray:
        """Which rows of (n, 2) wheel speeds, or (n, 3) with acts, may be acted
        on; the others are counted by reason and their robots hold still this tick."""
        actions = np.asarray(actions, np.float64)
        if actions.ndim != 2 or actions.shape[0] != self.n or actions.shape[1] not in (ACTION_LEN, ACTION_WIDTH):
            self.rejected["wrong shape"] += self.n
            return np.zeros(self.n, np.bool_)
        why = self._refusals(actions, np.arange(self.n))
        ok = why < 0
        if not ok.all():  # count the refused by reason (most ticks refuse nothing)
            for k in (NOT_FINITE, OVER_LIMIT, UNKNOWN_ACT):
                self.rejected[REJECT_REASONS[k]] += int((why == k).sum())
        return ok

    def apply(self, actions: np.ndarray, ok: np.ndarray | None = None) -> None:
        """Integrate one control period from validated wheel speeds (rows with
        ok False, finished robots and absent agents hold still)."""
        if ok is None:
            ok = self.validate(actions)
        wheels = np.zeros((self.n, ACTION_LEN))
        acts = np.zeros(self.n, np.int64)
        if np.shape(actions) in ((self.n, ACTION_LEN), (self.n, ACTION_WIDTH)):
            actions = np.asarray(actions, np.float64)
            wheels[ok] = actions[ok, :ACTION_LEN]
            if actions.shape[1] == ACTION_WIDTH:
                acts[ok] = actions[ok, -1].astype(np.int64)
        wheels = self._limit(wheels)
        self.rab_sent[ok] = self.rab_next[ok]  # a refused action's broadcast is dropped with it
        self.rab_next[...] = self.rab_sent
        before = self.pose[:, :2].copy()
        moving = ok & ~self.finished & self.present & self.in_world
        if self.metabolism is not None:  # the start-of-tick zones: where the robot was when it acted
            self.metabolism.step(acts, self.zones, moving, self.pose[:, :2], self.tick)
            self.finished |= ~self.metabolism.alive  # a dead robot stops, an obstacle to the others
        self.bodies.drive(wheels, self.axle, moving, pinned=~self.present & self.in_world)
        self.path_length += np.hypot(*(self.pose[:, :2] - before).T)
        self.tick += 1
        self._obstacles_at(self.tick)
        self._update_zones()
        if self.tick % self.scenario.checkpoint == 0:  # the physics restarts from its saved state, in every runtime
            self.checkpointed = self.snapshot()
            self._rebuild_bodies(self.checkpointed)

    def _limit(self, wheels: np.ndarray) -> np.ndarray:
        """The model's forward-speed and turn-rate limits scale the wheel speeds down."""
        out = np.empty((self.n, ACTION_LEN))
        limited(np.ascontiguousarray(wheels, np.float64), self.axle, self.max_speed, self.max_turn, out)
        return out

    def _obstacles_at(self, tick: int) -> None:
        for k, o in enumerate(self.scenario.obstacles):
            on = o.present(tick)
            self.seg_on[self.obstacle_segs[k]] = self.obstacle_layer[k] if on else 0
            if o.solid:
                self.bodies.set_obstacle(k, np.array(o.rect) if on else None)

    def _update_zones(self) -> None:
        self.zones[:] = 0
        xy = self.pose[:, :2]
        for z in self.scenario.zones:
            self.zones |= np.where(z.contains(xy), 1 << ZONE_KINDS.index(z.kind), 0)
        for o in self.scenario.obstacles:  # resources: usable within their reach while present
            if o.zone is not None and o.present(self.tick):
                near = np.hypot(xy[:, 0] - o.centre[0], xy[:, 1] - o.centre[1]) <= o.reach
                self.zones |= np.where(near, 1 << ZONE_KINDS.index(o.zone), 0)

    def finish(self, agents) -> None:
        """These robots are done for good (the run's goals say so): from the next tick they hold still,
        obstacles to the others.  A checkpoint taken this tick says so too (the world process saves it)."""
        self.finished[agents] = True
        if self.checkpointed is not None and int(self.checkpointed["tick"]) == self.tick:
            self.checkpointed["finished"][agents] = True

    def done(self) -> bool:
        """The world's own end: its last tick, or its metabolism's rule (a runner may end a run sooner:
        swarm.engines.goals)."""
        if self.tick >= self.scenario.max_ticks:
            return True
        return self.metabolism is not None and self.metabolism.done()

    def enter(self, agents) -> None:
        """Parked robots come in: at their given starts, or drawn (in this
        order) clear of the walls and of every robot already in the world."""
        agents = [int(a) for a in agents if not self.in_world[a]]
        if not agents:
            return
        inside = np.flatnonzero(self.in_world)
        poses = self.scenario.place(agents, self.pose[inside, :2], self.radius[inside], self.tick)
        for a, pose in zip(agents, poses, strict=True):
            self.bodies.enter(a, pose)
            self.start_pose[a] = pose
            self.in_world[a] = True
        self._update_zones()

    # ------------------------------------------------------------ persistence

    STATE = ("in_world", "present", "finished", "start_pose", "path_length", "zones")
    BODY_STATE = ("distance", "collisions", "blocked_seconds", "contact", "motion")

    def snapshot(self) -> dict[str, np.ndarray]:
        """What a restarted world resumes from (arrays only), pymunk's cached
        contacts included.  Chipmunk also carries a position correction from
        one step to the next that pymunk cannot read, so a snapshot is exact
        only where every runtime restarts its physics from it: at the
        scenario's checkpoints (`apply`), where the world server saves."""
        out = {k: np.array(getattr(self, k)) for k in self.STATE}
        out.update({f"body_{k}": np.array(getattr(self.bodies, k)) for k in self.BODY_STATE})
        out["pose"] = self.pose.copy()
        out["velocity"] = self.bodies.velocities()
        out.update(self.bodies.contacts())
        out["tick"] = np.array(self.tick)
        out["sim_seconds"] = np.array(self.bodies.sim_seconds)
        out["rejected"] = np.array([self.rejected[k] for k in REJECT_REASONS])
        if self.rab_sent.size:
            out["rab_sent"] = self.rab_sent.copy()
        if self.metabolism is not None:
            out.update(self.metabolism.snapshot())
        return out

    def restore(self, state: dict[str, np.ndarray]) -> None:
        for k in self.STATE:
            getattr(self, k)[...] = state[k]
        self.tick = int(state["tick"])
        self.rejected = dict.fromkeys(REJECT_REASONS, 0)
        self.rejected.update({k: int(v) for k, v in zip(REJECT_REASONS, state["rejected"], strict=False)})
        if "rab_sent" in state:
            self.rab_sent[...] = state["rab_sent"]
            self.rab_next[...] = self.rab_sent
        if self.metabolism is not None:
            self.metabolism.restore(state)
        self._rebuild_bodies(state)
        self._update_zones()

    def _rebuild_bodies(self, state: dict[str, np.ndarray]) -> None:
        """A fresh physics space from a snapshot (the same one in every runtime): bodies,
        their velocities and counters, the obstacles present now, the cached contacts."""
        self.bodies = self._new_bodies(state["pose"])
        for k in self.BODY_STATE:
            getattr(self.bodies, k)[...] = state[f"body_{k}"]
        self.bodies.sim_seconds = float(state["sim_seconds"])
        self.bodies.set_velocities(state["velocity"])
        self._obstacles_at(self.tick)
        if "contacts_f" in state:
            self.bodies.take_contacts(state)

    def remove_agent(self, agent: int) -> None:
        """The agent is gone: its body stops where it is and stays an obstacle."""
        self.present[agent] = False


def default_cell(s: ArenaScenario) -> float:
    """Index cell: a robot diameter and a quarter, at least 1/256 of the arena's side.  Crowds set it:
    a ray there ends within a cell or two, and a smaller cell holds fewer discs to test (`swarm bench
    arena`'s 1000 lasers sense in 16% less time than with two diameters; sparse worlds cost the same)."""
    r = max(g.robot.radius for g in s.groups)
    return max(2.5 * r, max(s.size) / 256)


__all__ = ["NO_HIT", "ArenaWorld", "default_cell"]
