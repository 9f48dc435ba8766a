"""Rerun recordings of arena runs (the grid's are swarm/recording/grid.py).

Layout (timeline `tick`; the record at tick t shows the world after tick t):

    run/meta              static: JSON of the scenario, robots' starts, goals and L_o, versions
    run/summary           static: JSON of the summary the run printed
    world/walls           static line strips, in the walls' colours
    world/zones           static boxes (rect zones) and circles (disc zones), labelled by kind
    world/goals           static points, one per robot with a goal
    world/obstacles       boxes of the scheduled obstacles present, logged when the set changes
    world/robots          one batched point cloud (radius = body), coloured by group
    world/headings        arrows, one per robot
    world/trajectories    line strips of every robot's path so far (logged at each flush)
    world/plans/<agent>   the path a controller planned (in process from its record(); distributed, sent
                          by its agent process on swarm/<run>/plans/<group>)
    world/optimum/<agent> static: the A* optimum from the robot's start to its goal (L_o; not for routes)
    …/<agent>/…           what explains a controller's choices, by the logs its registry entry names
                          (ControllerSpec.records: its map, its fields, its channels; in process, and a
                          map from its publications when distributed): each log's module lists its paths;
                          a controller whose entry names none: its record() by shape (swarm/recording/records.py;
                          distributed, sent by its agent process on swarm/<run>/records/<group>)
    metrics/<name>        reached, collisions, distance, agents_alive, tick_ms, rejected_messages
                          (in-process: the actions the world refused)
    metrics/robots/<name> per robot, one scalar each: path_length, collisions, in_goal, finished (dwelt)

Shown north up: rerun's 2D views grow y downwards, so y is logged negated.
Ticks are buffered and sent with `send_columns` every `flush_every` ticks.
"""

from __future__ import annotations

import json
import math
import sys

import numpy as np

from agents.controllers.arena import record_of
from swarm.core.registry import resolve
from swarm.engines.goals import ArenaGoals, optimum_planner
from swarm.recording.grid import FORMAT_VERSION, software_versions
from swarm.recording.sinks import stream_to

RECORD_LOG = "swarm.recording.records:RecordLog"

ARENA_METRICS = ("reached", "collisions", "distance", "agents_alive", "tick_ms", "rejected_messages")
ROBOT_SERIES = ("path_length", "collisions", "in_goal", "finished")
GROUP_COLOURS = ((40, 160, 40), (220, 120, 20), (60, 90, 220), (200, 40, 140), (30, 170, 190), (150, 150, 30))


def flip(xy: np.ndarray) -> np.ndarray:
    out = np.array(xy, np.float32, copy=True)
    out[..., 1] *= -1
    return out


def arena_meta(scenario, world, goals: ArenaGoals, run_id: str, runtime: str) -> dict:
    """What a reader needs to interpret the recording: taken at the first tick
    recorded, when the robots that start the run are in the world (a robot
    that joins later has no start or L_o here, and no row in `swarm report`)."""
    inside = np.flatnonzero(world.in_world).tolist()
    goals.fill_optimum(world)
    return {"kind": "arena", "run_id": run_id, "runtime": runtime, "scenario": scenario.describe(),
            "name": scenario.name, "controller": scenario.controller, "agents": scenario.agents,
            "seed": scenario.seed, "noise": scenario.noise.level, "control_period": scenario.control_period,
            "goal_radius": scenario.goal_radius, "max_ticks": scenario.max_ticks,
            "controllers": [g.controller for g in scenario.groups for _ in range(g.count)],
            "starts": [world.start_pose[a].round(6).tolist() if a in inside else None for a in range(world.n)],
            "walls": [{"shape": w.shape, "coords": list(w.coords), "colour": list(w.colour)} for w in scenario.walls],
            "obstacles": [{"rect": list(o.rect), "colour": list(o.colour), "name": o.name, "zone": o.zone,
                           "appear": o.appear, "vanish": o.vanish} for o in scenario.obstacles],
            "goals": [None if not goals.has_goal[a] else goals.goal[a].round(6).tolist() for a in range(world.n)],
            "optimal_lengths": [v if v is not None and math.isfinite(v) else None for v in goals.optimum]}  # fmt: skip


def records_of(scenario) -> list[tuple[str, ...]]:
    """Each robot's logs ("module:Class"): those its controller's registry entry names, or the log that
    shows any record() by its shape (swarm.recording.records) for one that names none (in process from
    the controller, distributed from what its agent process sends on records/<group>)."""
    specs = scenario.known_controllers
    return [(specs[g.controller].records if g.controller in specs else ()) or (RECORD_LOG,)
            for g in scenario.groups for _ in range(g.count)]  # fmt: skip


def blueprint(rrb, scenario, logs: list[tuple[str, ...]]):
    """The viewer's layout: the arena, the run's plots, and beside them what explains each group's
    controller (its logs' `views`, for the group's first robot)."""
    plots = [rrb.TimeSeriesView(origin=f"/metrics/{n}", name=n.replace("_", " ")) for n in ARENA_METRICS[:3]]
    explained, first = [], 0
    for g in scenario.groups:
        for ref in logs[first] if first < len(logs) else ():
            views = getattr(resolve(ref), "views", None)
            explained += views(rrb, first, g.controller) if views is not None else []
        first += g.count
    columns = [rrb.Spatial2DView(origin="/world", name="arena"), rrb.Vertical(*plots)]
    if explained:
        columns.append(rrb.Tabs(*explained))
    return rrb.Blueprint(rrb.Horizontal(*columns, column_shares=[3, 2, 2][: len(columns)]), collapse_panels=True)


class ArenaRecorder:
    def __init__(self, path, world, goals: ArenaGoals, meta: dict, viewer: str | None = None, flush_every: int = 256,
                 controllers=None):  # fmt: skip
        """`goals`: the run's (swarm.engines.goals); `meta`: run_id and runtime; the rest (arena_meta)
        is taken at the first tick, when the robots that start the run are in the world."""
        import rerun as rr
        import rerun.blueprint as rrb

        self.rr, self.world, self.goals, self.flush_every = rr, world, goals, flush_every
        self.controllers = controllers  # in-process: their planned paths are recorded
        from pathlib import Path

        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.rec = rr.RecordingStream("swarm", recording_id=str(meta.get("run_id", "run")))
        self._records_of = records_of(world.scenario)
        self._flush = stream_to(rr, self.rec, str(self.path), viewer, blueprint(rrb, world.scenario, self._records_of))
        self._meta_given = meta
        self.meta: dict = {}
        n = world.n
        group = np.concatenate([np.full(g.count, k) for k, g in enumerate(world.scenario.groups)])
        self.colours = np.array([GROUP_COLOURS[k % len(GROUP_COLOURS)] for k in group], np.uint8).reshape(n, 3)
        self._ticks: list[int] = []
        self._pose: list[np.ndarray] = []
        self._robots: dict[str, list[np.ndarray]] = {k: [] for k in ROBOT_SERIES}
        self._metrics: dict[str, list[float]] = {k: [] for k in ARENA_METRICS}
        self._paths = world.pose[:, None, :2].astype(np.float32)  # (n, T, 2): every robot's path so far
        self._obstacles_on: tuple | None = None
        self._plans_logged: set[int] = set()
        self._logs: dict = {}  # each controller log (ControllerSpec.records) in use, by its class
        self._quiet: set[int] = set()  # robots whose record() failed: left out of the recording
        self._published = None
        self._static_done = False

    def _log_static(self) -> None:
        rr, rec, w, s = self.rr, self.rec, self.world, self.world.scenario
        self._static_done = True
        given = self._meta_given
        built = arena_meta(s, w, self.goals, given.get("run_id", "run"), given.get("runtime", "in-process"))
        self.meta = {"format": FORMAT_VERSION, **built, **self._meta_given, "versions": software_versions()}
        rec.log("run/meta", rr.AnyValues(meta=json.dumps(self.meta)), rr.TextDocument(json.dumps(self.meta, indent=1)),
                static=True)  # fmt: skip
        self._log_walls()
        self._log_zones()
        goals = np.flatnonzero(self.goals.has_goal & w.in_world)
        if len(goals):
            rec.log(
                "world/goals",
                rr.Points2D(
                    flip(self.goals.goal[goals]),
                    radii=s.goal_radius / 3,
                    colors=self.colours[goals],
                    labels=[f"goal {a}" for a in goals],
                    draw_order=2.0,
                ),
                static=True,
            )
        rec.log("world/robots", rr.Points2D.from_fields(radii=w.radius.astype(np.float32), colors=self.colours,
                                                        draw_order=5.0), static=True)  # fmt: skip
        self._log_optimum(goals)

    def _log_walls(self) -> None:
        """The walls as line strips (a rectangle closed on itself), static."""
        rr, rec, s = self.rr, self.rec, self.world.scenario
        strips, colours = [], []
        for wall in s.walls:
            c = wall.coords
            pts = ([(c[0], c[1]), (c[2], c[1]), (c[2], c[3]), (c[0], c[3]), (c[0], c[1])] if wall.shape == "rect"
                   else [(c[0], c[1]), (c[2], c[3])])  # fmt: skip
            strips.append(flip(np.array(pts)))
            colours.append(wall.colour)
        if strips:
            rec.log("world/walls", rr.LineStrips2D(strips, colors=colours, radii=0.004, draw_order=1.0), static=True)

    def _log_zones(self) -> None:
        """The rectangular zones as boxes and the disc zones as circles, static."""
        rr, rec, s = self.rr, self.rec, self.world.scenario
        boxes = [z for z in s.zones if z.shape == "rect"]
        if boxes:
            centres = flip(
                np.array([((z.coords[0] + z.coords[2]) / 2, (z.coords[1] + z.coords[3]) / 2) for z in boxes])
            )
            halves = np.array([((z.coords[2] - z.coords[0]) / 2, (z.coords[3] - z.coords[1]) / 2) for z in boxes])
            rec.log(
                "world/zones",
                rr.Boxes2D(
                    centers=centres,
                    half_sizes=halves,
                    labels=[z.kind for z in boxes],
                    colors=[(120, 200, 120)] * len(boxes),
                    draw_order=0.5,
                ),
                static=True,
            )
        discs = [z for z in s.zones if z.shape == "disc"]
        if discs:
            a = np.linspace(0, 2 * math.pi, 33)
            circles = [
                flip(np.column_stack([z.coords[0] + z.coords[2] * np.cos(a), z.coords[1] + z.coords[2] * np.sin(a)]))
                for z in discs
            ]
            rec.log(
                "world/zone_discs",
                rr.LineStrips2D(
                    circles, labels=[z.kind for z in discs], radii=0.004, colors=[(120, 200, 120)] * len(discs)
                ),
                static=True,
            )

    def _log_optimum(self, robots) -> None:
        """The A* optimum (1 cm, 4 cm clearance: L_o) from each robot's start to its goal, for robots
        driving to one goal (not a route)."""
        w, s = self.world, self.world.scenario
        routed = [g.route is not None for g in s.groups for _ in range(g.count)]
        planner = None
        for a in robots:
            if routed[a]:
                continue
            planner = planner or optimum_planner(s.size, s.walls)
            length, points = planner.plan(tuple(w.start_pose[a, :2]), tuple(self.goals.goal[a]))
            if np.isfinite(length) and len(points) > 1:
                strip = self.rr.LineStrips2D([flip(points)], colors=[(160, 160, 160)], radii=0.0015, draw_order=2.5)
                self.rec.log(f"world/optimum/{a}", strip, static=True)

    # -------------------------------------------------------------------- ticks

    def capture(self, tick: int, present: np.ndarray | None = None, tick_ms: float = 0.0, rejected: int = 0) -> None:
        w = self.world
        if not self._static_done:
            self._log_static()
        self._ticks.append(tick)
        self._pose.append(w.pose.astype(np.float32).copy())
        in_goal, goals = np.zeros(w.n), self.goals
        if goals.has_goal.any():
            dist = np.hypot(*(w.pose[:, :2] - np.nan_to_num(goals.goal)).T)
            in_goal = (goals.has_goal & (dist < w.scenario.goal_radius)).astype(np.float64)
        for name, values in (("path_length", w.path_length), ("collisions", w.bodies.collisions), ("in_goal", in_goal),
                             ("finished", w.finished)):  # fmt: skip
            self._robots[name].append(np.asarray(values, np.float64).copy())
        alive = w.n if present is None else int(np.asarray(present).sum())
        for name, value in (("reached", float(w.finished.sum())), ("collisions", float(w.bodies.collisions.sum())),
                            ("distance", float(w.bodies.distance.sum())), ("agents_alive", float(alive)),
                            ("tick_ms", tick_ms), ("rejected_messages", float(rejected))):  # fmt: skip
            self._metrics[name].append(value)
        on = tuple(o.present(w.tick) for o in w.scenario.obstacles)
        if on != self._obstacles_on:
            self._obstacles_on = on
            self._log_obstacles(tick, on)
        if self.controllers is not None:
            records = self._records()  # once a tick: the logs below share them
            self._log_plans(tick, records)
            self._log_explanations(tick, records)
        if len(self._ticks) >= self.flush_every:
            self.flush()

    def _records(self) -> list[dict]:
        """Each controller's record(): one that raises or gives no dict is told once and shows nothing."""
        out = []
        for a, c in enumerate(self.controllers):
            record: dict = {}
            if a not in self._quiet:
                record, why = record_of(c)
                if why is not None:
                    self._quiet.add(a)
                    print(f"swarm: the recording leaves out robot {a}'s record(): {why}", file=sys.stderr)
            out.append(record)
        return out

    def _log_obstacles(self, tick: int, on: tuple) -> None:
        """The boxes present now (resources among them, labelled by name)."""
        rr = self.rr
        here = [o for o, present in zip(self.world.scenario.obstacles, on, strict=True) if present]
        rects = np.array([o.rect for o in here]).reshape(-1, 4)
        self.rec.set_time("tick", sequence=tick)
        self.rec.log("world/obstacles", rr.Boxes2D(
            centers=flip((rects[:, :2] + rects[:, 2:]) / 2), half_sizes=(rects[:, 2:] - rects[:, :2]) / 2,
            colors=[o.colour for o in here], labels=[o.name or "obstacle" for o in here], draw_order=1.5,
        ))  # fmt: skip

    def _log_plans(self, tick: int, records: list[dict]) -> None:
        for a in range(len(self.controllers)):
            if a not in self._plans_logged:
                path = np.asarray(records[a].get("path", np.zeros((0, 2))))
                if len(path) > 1:
                    self.log_plan(tick, a, path)

    def _log_explanations(self, tick: int, records: list[dict]) -> None:
        """What explains each controller's choices, by the logs its registry entry names (its map, its
        neural fields, its basal-ganglia channels), each log made at its first use."""
        for a, refs in enumerate(self._records_of):
            for ref in refs:
                self._log(resolve(ref)).capture(tick, a, records[a], self.world.pose[a, :2])

    def _log(self, cls):
        if cls not in self._logs:
            self._logs[cls] = cls(self.rr, self.rec, self.colours)
        return self._logs[cls]

    def log_published_map(self, tick: int, agent: int, data) -> None:
        """Distributed: a robot's map from its publication on the map key space."""
        from agents.controllers.navigation.recording import MapLog, PublishedMaps

        if self._published is None:
            self._published = PublishedMaps()
        record = self._published.update(agent, data)
        if record is not None:
            self._log(MapLog).capture(tick, agent, record, self.world.pose[agent, :2])

    def log_record(self, tick: int, agent: int, values: dict) -> None:
        """Distributed: a robot's record() as its agent process sent it (the record log of a controller
        whose entry names no log of its own)."""
        if 0 <= agent < self.world.n and self._records_of[agent] == (RECORD_LOG,):
            self._log(resolve(RECORD_LOG)).capture(tick, agent, values)

    def log_plan(self, tick: int, agent: int, path: np.ndarray) -> None:
        """A controller's planned path, at the tick it was planned."""
        self._plans_logged.add(agent)
        self.rec.set_time("tick", sequence=tick)
        colour = self.colours[agent] if 0 <= agent < len(self.colours) else (200, 200, 200)
        self.rec.log(f"world/plans/{agent}", self.rr.LineStrips2D([flip(path)], colors=[colour], radii=0.002,
                                                                  draw_order=3.0))  # fmt: skip

    def flush(self) -> None:
        if not self._ticks:
            return
        rr, rec = self.rr, self.rec
        ticks = np.array(self._ticks, np.int64)
        pose = np.stack(self._pose)  # (T, n, 3)
        self._ticks, self._pose = [], []
        index = [rr.TimeColumn("tick", sequence=ticks)]
        n = pose.shape[1]
        rec.send_columns(
            "world/robots",
            indexes=index,
            columns=rr.Points2D.columns(positions=flip(pose[..., :2].reshape(-1, 2))).partition([n] * len(ticks)),
        )
        length = 1.5 * np.repeat(self.world.radius[None], len(ticks), axis=0).ravel()
        theta = pose[..., 2].ravel()
        vectors = np.column_stack([length * np.cos(theta), -length * np.sin(theta)])
        rec.send_columns(
            "world/headings",
            indexes=index,
            columns=rr.Arrows2D.columns(
                origins=flip(pose[..., :2].reshape(-1, 2)),
                vectors=vectors,
                colors=np.tile(self.colours, (len(ticks), 1)),
            ).partition([n] * len(ticks)),
        )
        for name in ARENA_METRICS:
            rec.send_columns(f"metrics/{name}", indexes=index,
                             columns=rr.Scalars.columns(scalars=np.array(self._metrics[name], np.float64)))  # fmt: skip
            self._metrics[name] = []
        for name in ROBOT_SERIES:
            values = np.stack(self._robots[name]).ravel()
            rec.send_columns(f"metrics/robots/{name}", indexes=index,
                             columns=rr.Scalars.columns(scalars=values).partition([n] * len(ticks)))  # fmt: skip
            self._robots[name] = []
        self._paths = paths = np.concatenate([self._paths, pose[..., :2].transpose(1, 0, 2)], axis=1)
        for log in self._logs.values():
            log.flush()
        rec.set_time("tick", sequence=int(ticks[-1]))
        rec.log("world/trajectories", rr.LineStrips2D([flip(p) for p in paths], colors=self.colours, radii=0.002,
                                                      draw_order=4.0))  # fmt: skip
        self._flush(rec, timeout_sec=0)  # on disk without waiting: a kill loses at most `flush_every` ticks

    def close(self, summary: dict | None = None) -> None:
        if not self._static_done:
            self._log_static()
        self.flush()
        if summary is not None:
            self.rec.log("run/summary", self.rr.AnyValues(summary=json.dumps(summary)), static=True)
        self._flush(self.rec)
        self.rec.disconnect()


def open_for_server(server, path, viewer: str | None) -> ArenaRecorder:
    """The recorder of a world process's arena run (swarm.world_process lends it to the server)."""
    meta = {"run_id": server.keys.run, "runtime": server.mode}
    return ArenaRecorder(path, server.world, server.kind.goals, meta, viewer=viewer)
