"""Arena scenarios: a continuous floor in metres, its walls, zones, scheduled
obstacles, the robots' model and the agent groups that run on it.

A TOML file with `kind = "arena"` (docs/arena.md lists every field):

    kind = "arena"
    size = [1.0, 1.0]                 # metres; x east, y north, origin south-west
    robot = "epuck"                   # animat | epuck | scout, or a [robot] table
    noise = "low"                     # none | low | high, or a [noise] table
    control_period = 0.064            # seconds per tick
    substeps = 4                      # physics steps per tick
    checkpoint = 50                   # ticks between physics checkpoints (exact resume)
    physics_strips = 1                # the floor cut along x into spaces stepped side by side
    max_ticks = 3000
    [[wall]]   rect = [x0, y0, x1, y1]  (or segment = [x0, y0, x1, y1]), colour = [r, g, b]
    [[zone]]   kind = "goal", rect = [...] or disc = [cx, cy, r]
    [[obstacle]] rect = [...], appear = 100, vanish = 400
    [[group]]  count = 1, controller = "carrot", start = [x, y, theta], goal = [x, y]
    [routes]   tour = [[x, y], ...]

Errors name the file and the field and say what is expected.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from swarm.core.errors import ScenarioError
from swarm.core.registry import ControllerSpec
from swarm.core.tables import no_unknown, typed
from world_server.arena import schema as fields
from world_server.arena.face.robots import MODELS, RobotModel
from world_server.arena.face.sensors import SENSORS, Sensors
from world_server.arena.face.sensors.zones import ZONE_KINDS
from world_server.arena.metabolism import MetabolismParams
from world_server.arena.sensors import NOISE_LEVELS, Noise

START_STREAM = 0x53544152  # keeps start-pose draws apart from every other use of the seed
GOAL_STREAM = 0x474F414C
SPACED_DRAWS = 200
MAX_DRAWS = 10_000
Colour = tuple[int, int, int]
GREY = (128, 128, 128)


@dataclass(frozen=True)
class Wall:
    shape: str  # rect | segment
    coords: tuple[float, float, float, float]
    colour: Colour = GREY
    name: str = ""


@dataclass(frozen=True)
class Zone:
    kind: str
    shape: str  # rect | disc
    coords: tuple[float, ...]
    name: str = ""

    def contains(self, xy: np.ndarray) -> np.ndarray:
        if self.shape == "rect":
            x0, y0, x1, y1 = self.coords
            return (xy[:, 0] >= x0) & (xy[:, 0] <= x1) & (xy[:, 1] >= y0) & (xy[:, 1] <= y1)
        cx, cy, r = self.coords
        return np.hypot(xy[:, 0] - cx, xy[:, 1] - cy) <= r


@dataclass(frozen=True)
class Obstacle:
    """A box present from tick `appear` until `vanish`.  A resource is one too:
    it carries a zone of its kind, a disc of radius `reach` round its centre,
    usable while it is present; a non-solid box is a mark only cameras see."""

    rect: tuple[float, float, float, float]
    appear: int = 0
    vanish: int | None = None  # tick at which it goes; None: stays
    colour: Colour = GREY
    name: str = ""
    solid: bool = True
    zone: str | None = None
    reach: float = 0.7

    def present(self, tick: int) -> bool:
        return tick >= self.appear and (self.vanish is None or tick < self.vanish)

    @property
    def centre(self) -> tuple[float, float]:
        return ((self.rect[0] + self.rect[2]) / 2, (self.rect[1] + self.rect[3]) / 2)


@dataclass(frozen=True)
class Group:
    count: int
    controller: str
    robot: RobotModel
    starts: tuple[tuple[float, float, float], ...] | None = None  # None: drawn with `clearance`
    clearance: float = 0.04
    goals: tuple[tuple[float, float], ...] | None = None  # one per robot, or one for all
    draw_goals: bool = False  # a goal per robot, drawn from (seed, agent) with the clearance
    route: str | None = None


@dataclass(frozen=True)
class ArenaScenario:
    name: str
    source: str
    size: tuple[float, float]
    groups: tuple[Group, ...]
    walls: tuple[Wall, ...] = ()
    zones: tuple[Zone, ...] = ()
    obstacles: tuple[Obstacle, ...] = ()
    routes: dict[str, tuple[tuple[float, float], ...]] = field(default_factory=dict)
    seed: int = 0
    control_period: float = 0.064
    substeps: int = 4
    checkpoint: int = 50  # ticks: the physics restarts from its saved state here, in every runtime (docs/arena.md)
    physics_strips: int = 1  # the floor cut along x into this many physics spaces, stepped side by side
    noise: Noise = field(default_factory=Noise)
    max_ticks: int = 3000
    goal_radius: float = 0.07  # a robot has reached its goal within this distance (DFT code: 7 cells)
    goal_dwell: int = 40  # ticks inside the goal radius that end its run (DFT supervisor: 20 x 128 ms)
    controller_params: dict[str, dict[str, Any]] = field(default_factory=dict)
    description: str = ""
    kind: str = "arena"
    metabolism: MetabolismParams | None = None  # E and Ep for every robot (the BG paper's survival task)
    # The arena controllers a group may name, from the controller registry (the scenario loader's).
    known_controllers: Mapping[str, ControllerSpec] = field(default_factory=dict, compare=False, repr=False)

    @property
    def agents(self) -> int:
        return sum(g.count for g in self.groups)

    def share_of(self, controller: str) -> str | None:
        """The key space the controller writes (swarm/<run>/<share>/<agent>), if any."""
        spec = self.known_controllers.get(controller)
        return None if spec is None else spec.shares

    @property
    def controller(self) -> str:
        names = sorted({g.controller for g in self.groups})
        return names[0] if len(names) == 1 else "+".join(names)

    def with_overrides(
        self,
        agents: int | None = None,
        controller: str | None = None,
        seed: int | None = None,
        start: tuple[float, ...] | None = None,
        goal: tuple[float, float] | None = None,
        noise: str | None = None,
        max_ticks: int | None = None,
        **_ignored,
    ) -> ArenaScenario:
        """Command-line changes; --start and --goal are for one-robot runs."""
        groups = list(self.groups)
        if agents is not None and agents != self.agents:
            if len(groups) != 1:
                raise ScenarioError("command line", "agents", "this scenario has several groups: "
                                    "change the counts in the file")  # fmt: skip
            g = groups[0]
            starts = g.starts if g.starts and len(g.starts) == agents else None  # else drawn
            # one robot's goal does not become a shared one: more robots get a goal each, drawn
            draw = g.draw_goals or (g.goals is not None and len(g.goals) != agents)
            groups[0] = replace(g, count=agents, starts=starts, goals=None if draw else g.goals, draw_goals=draw)
        if controller is not None:
            _check_controller(controller, self.known_controllers, "command line", "controller")
            groups = [replace(g, controller=controller) for g in groups]
        if start is not None or goal is not None:
            if sum(g.count for g in groups) != 1:
                raise ScenarioError("command line", "start/goal", "--start and --goal are for one-robot runs; "
                                    "use --agents 1 or set starts in the file")  # fmt: skip
            g = groups[0]
            if start is not None:
                theta = start[2] if len(start) > 2 else (g.starts[0][2] if g.starts else 0.0)
                g = replace(g, starts=((float(start[0]), float(start[1]), float(theta)),))
            if goal is not None:
                g = replace(g, goals=((float(goal[0]), float(goal[1])),), route=None, draw_goals=False)
            groups[0] = g
        new = replace(
            self,
            groups=tuple(groups),
            seed=self.seed if seed is None else seed,
            noise=self.noise if noise is None else replace(self.noise, level=noise),
            max_ticks=self.max_ticks if max_ticks is None else max_ticks,
        )
        check_arena(new, "command line")
        return new

    def agent_processes(self, agents: int) -> list[tuple[str, int]]:
        """(controller, robots) for every kind of agent process a run of `agents` robots needs: each
        group's robots run its own controller."""
        if len(self.groups) == 1:
            return [(self.groups[0].controller, agents)]
        counts: dict[str, int] = {}
        for g in self.groups:
            counts[g.controller] = counts.get(g.controller, 0) + g.count
        return list(counts.items())

    def describe(self) -> dict[str, Any]:
        return {"name": self.name, "kind": "arena", "seed": self.seed, "size": list(self.size),
                "agents": self.agents, "controller": self.controller, "noise": self.noise.level,
                "checkpoint": self.checkpoint,
                # named only when more than one: a default run's description (which its saved states are
                # checked against) lists no physics option
                **({"physics_strips": self.physics_strips} if self.physics_strips > 1 else {}),
                "walls": len(self.walls), "zones": len(self.zones), "obstacles": len(self.obstacles),
                "groups": [{"count": g.count, "controller": g.controller, "robot": g.robot.name}
                           for g in self.groups]}  # fmt: skip

    def physics_halo(self) -> float:
        """How far beyond a physics strip's edges its space holds other strips' robots (as ghosts): two
        contact reaches, each a diameter of the largest robot and a control period of two robots closing
        in at twice the top speed (a pushed robot may outrun its own drive).  The first reach holds every
        robot that may touch one of the strip's own; the second, the robots that push those, so that a
        ghost moves as its owner does (docs/arena.md has the crowds measured with one reach and two)."""
        models = [g.robot for g in self.groups]
        reach = 2 * max(m.radius for m in models) + 4 * max(m.max_speed for m in models) * self.control_period
        return 2 * reach

    # ------------------------------------------------------------ geometry

    def wall_rects(self) -> np.ndarray:
        return np.array([w.coords for w in self.walls if w.shape == "rect"], np.float64).reshape(-1, 4)

    def wall_segments(self) -> np.ndarray:
        return np.array([w.coords for w in self.walls if w.shape == "segment"], np.float64).reshape(-1, 4)

    def robot_models(self) -> list[RobotModel]:
        return [g.robot for g in self.groups for _ in range(g.count)]

    def start_poses(self) -> np.ndarray:
        """Every robot's start pose: given, or drawn from (seed, agent) with the
        group's clearance from walls, obstacles present at tick 0 and the robots
        placed before it."""
        return self.place(range(self.agents), np.zeros((0, 2)), np.zeros(0), 0)

    def place(self, agents, occupied: np.ndarray, occupied_radius: np.ndarray, tick: int) -> np.ndarray:
        """Start poses for `agents` (in this order) entering at `tick` beside robots
        already at `occupied` (x, y) with these radii: the given starts, or drawn."""
        groups = [(gi, g) for gi, g in enumerate(self.groups) for _ in range(g.count)]
        first = {}
        for k, (gi, _) in enumerate(groups):
            first.setdefault(gi, k)
        placed = [tuple(p) for p in np.asarray(occupied, np.float64).reshape(-1, 2)]
        radii = [float(r) for r in occupied_radius]
        poses = []
        for agent in agents:
            gi, g = groups[agent]
            if g.starts is not None:
                pose = g.starts[agent - first[gi]]
            else:
                pose = self._draw_pose(agent, g.robot.radius + g.clearance, placed, radii, f"group {gi + 1}", tick)
            poses.append(pose)
            placed.append(pose[:2])
            radii.append(g.robot.radius)
        return np.array(poses, np.float64).reshape(-1, 3)

    def _draw_pose(self, agent: int, clearance: float, placed, radii, where: str,
                   tick: int = 0) -> tuple[float, float, float]:  # fmt: skip
        rng = np.random.default_rng([self.seed, START_STREAM, agent])
        blocks = self.blocking_rects(tick)
        segs = self.wall_segments()
        w, h = self.size
        for _ in range(MAX_DRAWS):
            x, y = rng.uniform(clearance, w - clearance), rng.uniform(clearance, h - clearance)
            theta = rng.uniform(0.0, 2 * math.pi)
            if clearance_at(np.array([[x, y]]), blocks, segs)[0] < clearance:
                continue
            if any(math.hypot(x - p[0], y - p[1]) < clearance + r for p, r in zip(placed, radii, strict=True)):
                continue
            return (float(x), float(y), float(theta))
        raise ScenarioError(self.source, f"{where}: starts", f"no free place with clearance {clearance:g} m for robot "
                            f"{agent} in {MAX_DRAWS} draws; give starts or fewer robots (--agents)")  # fmt: skip

    def blocking_rects(self, tick: int) -> np.ndarray:
        """Wall rectangles plus the obstacles present at `tick`."""
        rects = [w.coords for w in self.walls if w.shape == "rect"]
        rects += [o.rect for o in self.obstacles if o.present(tick) and o.solid]
        return np.array(rects, np.float64).reshape(-1, 4)

    def goals(self) -> list[tuple[float, float] | None]:
        """Every robot's goal (None: it has none).  Drawn goals keep the group's
        clearance from walls and, where there is room, twice the goal radius
        from the goals of lower ids, so robots do not crowd one spot; each comes
        from (seed, agent) and the goals before it, never from who joined when."""
        if "_goals" in self.__dict__:
            return self.__dict__["_goals"]
        out: list[tuple[float, float] | None] = []
        drawn: list[tuple[float, float]] = []
        agent = 0
        for gi, g in enumerate(self.groups):
            for k in range(g.count):
                if g.draw_goals:
                    goal = self._draw_goal(agent, g.robot.radius + g.clearance, drawn, f"group {gi + 1}")
                    drawn.append(goal)
                    out.append(goal)
                else:
                    out.append(None if g.goals is None else g.goals[k if len(g.goals) > 1 else 0])
                agent += 1
        self.__dict__["_goals"] = out  # frozen: cached beside the fields, not through them
        return out

    def _draw_goal(self, agent: int, clearance: float, drawn, where: str) -> tuple[float, float]:
        """Apart from the goals before it when there is room (SPACED_DRAWS tries), else
        anywhere clear of the walls: a world of many slots never fails for it."""
        rng = np.random.default_rng([self.seed, GOAL_STREAM, agent])
        blocks, segs = self.blocking_rects(0), self.wall_segments()
        w, h = self.size
        for attempt in range(MAX_DRAWS):
            x, y = rng.uniform(clearance, w - clearance), rng.uniform(clearance, h - clearance)
            if clearance_at(np.array([[x, y]]), blocks, segs)[0] < clearance:
                continue
            if attempt >= SPACED_DRAWS or all(math.hypot(x - gx, y - gy) >= 2 * self.goal_radius for gx, gy in drawn):
                return (float(x), float(y))
        raise ScenarioError(self.source, f"{where}: goals", f"no place {clearance:g} m clear of the walls for goal "
                            f"{agent} in {MAX_DRAWS} draws; give goals")  # fmt: skip


def clearance_at(xy: np.ndarray, rects: np.ndarray, segs: np.ndarray) -> np.ndarray:
    """Distance from each point to the nearest rectangle or segment (0 inside a rectangle)."""
    best = np.full(len(xy), np.inf)
    if len(rects):
        dx = np.maximum(np.maximum(rects[None, :, 0] - xy[:, None, 0], xy[:, None, 0] - rects[None, :, 2]), 0.0)
        dy = np.maximum(np.maximum(rects[None, :, 1] - xy[:, None, 1], xy[:, None, 1] - rects[None, :, 3]), 0.0)
        best = np.minimum(best, np.hypot(dx, dy).min(axis=1))
    if len(segs):
        a, b = segs[None, :, :2], segs[None, :, 2:]
        ab = b - a
        t = np.clip(((xy[:, None, :] - a) * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-18), 0.0, 1.0)
        near = a + t[..., None] * ab
        best = np.minimum(best, np.hypot(*(xy[:, None, :] - near).transpose(2, 0, 1)).min(axis=1))
    return best


# --------------------------------------------------------------------- parsing

_TOP = set(fields.TOP)  # the tables' keys are the schema's (world_server/arena/schema.py)


def _tabled(keys: Iterable[str] = ()) -> tuple[str, ...]:
    """The sensors a scenario's [robot.<name>] and [noise] tables may name: those with fields (of the
    installed ones, those among `keys`, imported now)."""
    return tuple(cls.name for cls in SENSORS.including(keys) if cls.field_names())


def parse_section(data: dict, text: str, source: str, name: str,
                  controllers: Mapping[str, ControllerSpec]) -> ArenaScenario:  # fmt: skip
    """The kind's scenario parser (world_server.WORLD_KINDS): parse_arena (`text` is not needed)."""
    return parse_arena(data, source, name, controllers)


def parse_arena(data: dict, source: str, default_name: str, controllers: Mapping[str, ControllerSpec]) -> ArenaScenario:
    """The ArenaScenario of a scenario file's tables.  `controllers`: the arena controllers a group
    may name (each may have its own [name] table)."""
    tables = [k for k in data if k in controllers]  # imports only the installed controllers it names
    no_unknown(data, _TOP | set(tables), source, "top level")
    size = _numbers(data, "size", source, "size", 2)
    if not all(0 < v <= 10_000 for v in size):
        raise ScenarioError(source, "size", f"expected two positive sizes in metres, got {list(size)}")
    robot = _robot(data.get("robot", "epuck"), source, "robot")
    kw: dict[str, Any] = {
        "name": _get(data, "name", str, source, default_name),
        "source": source,
        "size": (size[0], size[1]),
        "description": _get(data, "description", str, source, ""),
    }
    for key in ("seed", "substeps", "checkpoint", "physics_strips", "max_ticks", "goal_dwell"):
        if key in data:
            kw[key] = _get(data, key, int, source)
    for key in ("control_period", "goal_radius"):
        if key in data:
            kw[key] = float(_get(data, key, (int, float), source))
    kw["noise"] = _noise(data.get("noise", "low"), source)
    kw["walls"] = tuple(_wall(w, source, f"wall {i + 1}") for i, w in enumerate(_list(data, "wall", source)))
    kw["zones"] = tuple(_zone(z, source, f"zone {i + 1}") for i, z in enumerate(_list(data, "zone", source)))
    obstacles = [_obstacle(o, source, f"obstacle {i + 1}") for i, o in enumerate(_list(data, "obstacle", source))]
    obstacles += [_resource(r, source, f"resource {i + 1}") for i, r in enumerate(_list(data, "resource", source))]
    kw["obstacles"] = tuple(obstacles)  # resources are obstacles that carry a zone
    routes = data.get("routes", {})
    if not isinstance(routes, dict):
        raise ScenarioError(source, "routes", "expected a [routes] table of name = [[x, y], ...]")
    kw["routes"] = {k: tuple(_point_list(v, source, f"routes.{k}", 2)) for k, v in routes.items()}
    groups = _list(data, "group", source)
    if not groups:
        raise ScenarioError(source, "group", "missing: add at least one [[group]] with count and controller")
    kw["groups"] = tuple(_group(g, robot, controllers, source, f"group {i + 1}") for i, g in enumerate(groups))
    kw["controller_params"] = {c: _table(data, c, source) for c in tables}
    kw["known_controllers"] = controllers
    if "metabolism" in data:
        try:
            kw["metabolism"] = MetabolismParams.from_table(_table(data, "metabolism", source))
        except ValueError as exc:
            field_name, _, message = str(exc).partition(": ")
            raise ScenarioError(source, field_name, message) from None
    scenario = ArenaScenario(**kw)
    check_arena(scenario, source)
    return scenario


def _robot(value, source: str, where: str) -> RobotModel:
    if isinstance(value, str):
        if value not in MODELS:
            raise ScenarioError(source, where, f"unknown robot model {value!r}; expected one of {', '.join(MODELS)} "
                                "or a [robot] table")  # fmt: skip
        return MODELS[value]
    if not isinstance(value, dict):
        raise ScenarioError(source, where, "expected a model name or a [robot] table")
    allowed = {*fields.ROBOT, *_tabled(value)}
    no_unknown(value, allowed, source, f"[{where}]")
    model = _robot(value.get("model", "epuck"), source, f"{where}.model")
    changes: dict[str, Any] = {"name": _get(value, "name", str, source, model.name, f"{where}.name")}
    for key in ("radius", "axle", "max_wheel_speed", "max_speed", "max_turn_rate"):
        if key in value:
            changes[key] = float(_get(value, key, (int, float), source, where=f"{where}.{key}"))
    if "colour" in value:
        changes["colour"] = _colour(value["colour"], source, f"{where}.colour")
    changes["sensors"] = _sensors(value, model.sensors, source, where)
    model = replace(model, **changes)
    for spec in model.sensors:
        try:
            spec.check(model)
        except ValueError as exc:
            field_name, _, message = str(exc).partition(": ")
            raise ScenarioError(source, f"{where}.{spec.name}.{field_name}", message) from None
    return model


def _sensors(value: dict, sensors: Sensors, source: str, where: str) -> Sensors:
    """A [robot] table's sensors: its `sensors` list (each named one kept or at its defaults, the
    others left out), then each [robot.<name>] table over that sensor's spec (adding it)."""
    if "sensors" in value:
        names, kinds = value["sensors"], SENSORS.names()
        if not isinstance(names, list) or not all(isinstance(n, str) and n in SENSORS for n in names):
            kinds = SENSORS.names()  # less an installed one that could not be loaded
            raise ScenarioError(source, f"{where}.sensors", f"expected a list of {', '.join(sorted(kinds))}")
        sensors = Sensors(**{k: (getattr(sensors, k) or True) if k in names else None for k in kinds})
    for key in _tabled(value):
        if key in value:
            table = _table(value, key, source, f"{where}.{key}")
            cls = SENSORS[key]
            no_unknown(table, set(cls.field_names()), source, f"[{where}.{key}]")
            try:
                sensors = sensors.changed(**{key: cls.from_table(table, getattr(sensors, key))})
            except ValueError as exc:
                field_name, _, message = str(exc).partition(": ")
                raise ScenarioError(source, f"{where}.{key}.{field_name}", message) from None
    return sensors


def _noise(value, source: str) -> Noise:
    if isinstance(value, str):
        if value not in NOISE_LEVELS:
            raise ScenarioError(source, "noise", f"unknown level {value!r}; expected one of {', '.join(NOISE_LEVELS)}")
        return Noise(level=value)
    if not isinstance(value, dict):
        raise ScenarioError(source, "noise", "expected a level (none, low, high) or a [noise] table")
    level = value.get("level", "low")
    base = _noise(level, source)
    scales = []
    for k in value:
        if k == "level":
            continue
        if k not in {*_tabled(value), "map"}:
            raise ScenarioError(source, f"noise.{k}", f"unknown sensor; expected level or one of "
                                f"{', '.join(sorted(_tabled()))}")  # fmt: skip
        scales.append((k, float(_get(value, k, (int, float), source, where=f"noise.{k}"))))
    return replace(base, scale=tuple(scales))


def _wall(w, source: str, where: str) -> Wall:
    if not isinstance(w, dict):
        raise ScenarioError(source, where, "expected a [[wall]] table")
    no_unknown(w, set(fields.WALL), source, f"[[wall]] ({where})")
    if ("rect" in w) == ("segment" in w):
        raise ScenarioError(source, where, "give exactly one of rect = [x0, y0, x1, y1] or segment = [x0, y0, x1, y1]")
    shape = "rect" if "rect" in w else "segment"
    coords = _numbers(w, shape, source, f"{where}.{shape}", 4)
    if shape == "rect":
        coords = _rect(coords, source, f"{where}.rect")
    elif coords[:2] == coords[2:]:
        raise ScenarioError(source, f"{where}.segment", "the two ends are the same point")
    return Wall(shape, coords, _colour(w.get("colour", list(GREY)), source, f"{where}.colour"),
                _get(w, "name", str, source, "", f"{where}.name"))  # fmt: skip


def _zone(z, source: str, where: str) -> Zone:
    if not isinstance(z, dict):
        raise ScenarioError(source, where, "expected a [[zone]] table")
    no_unknown(z, set(fields.ZONE), source, f"[[zone]] ({where})")
    kind = _get(z, "kind", str, source, None, f"{where}.kind")
    if kind not in ZONE_KINDS:
        raise ScenarioError(source, f"{where}.kind", f"unknown {kind!r}; expected one of {', '.join(ZONE_KINDS)}")
    if ("rect" in z) == ("disc" in z):
        raise ScenarioError(source, where, "give exactly one of rect = [x0, y0, x1, y1] or disc = [cx, cy, r]")
    if "rect" in z:
        return Zone(kind, "rect", _rect(_numbers(z, "rect", source, f"{where}.rect", 4), source, f"{where}.rect"),
                    z.get("name", ""))  # fmt: skip
    disc = _numbers(z, "disc", source, f"{where}.disc", 3)
    if disc[2] <= 0:
        raise ScenarioError(source, f"{where}.disc", "the radius must be positive")
    return Zone(kind, "disc", disc, z.get("name", ""))


def _obstacle(o, source: str, where: str) -> Obstacle:
    if not isinstance(o, dict):
        raise ScenarioError(source, where, "expected an [[obstacle]] table")
    no_unknown(o, set(fields.OBSTACLE), source, f"[[obstacle]] ({where})")
    rect = _rect(_numbers(o, "rect", source, f"{where}.rect", 4), source, f"{where}.rect")
    appear = _get(o, "appear", int, source, 0, f"{where}.appear")
    vanish = _get(o, "vanish", int, source, None, f"{where}.vanish")
    if appear < 0 or (vanish is not None and vanish <= appear):
        raise ScenarioError(source, where, f"expected 0 <= appear < vanish (ticks), got appear {appear}, "
                            f"vanish {vanish}")  # fmt: skip
    return Obstacle(rect, appear, vanish, _colour(o.get("colour", list(GREY)), source, f"{where}.colour"),
                    o.get("name", ""))  # fmt: skip


def _resource(r, source: str, where: str) -> Obstacle:
    if not isinstance(r, dict):
        raise ScenarioError(source, where, "expected a [[resource]] table")
    no_unknown(r, set(fields.RESOURCE), source, f"[[resource]] ({where})")
    kind = _get(r, "kind", str, source, None, f"{where}.kind")
    if kind not in fields.RESOURCE_GREY:
        raise ScenarioError(
            source, f"{where}.kind", f"unknown {kind!r}; expected one of {', '.join(fields.RESOURCE_GREY)}"
        )
    cx, cy = _numbers(r, "centre", source, f"{where}.centre", 2)
    size = float(_get(r, "size", (int, float), source, fields.RESOURCE_SIZE, f"{where}.size"))
    reach = float(_get(r, "reach", (int, float), source, fields.RESOURCE_REACH, f"{where}.reach"))
    if not (0 < size <= 10 and 0 < reach <= 100):
        raise ScenarioError(source, where, f"expected a size of 0-10 m and a reach of 0-100 m, got {size}, {reach}")
    appear = _get(r, "appear", int, source, 0, f"{where}.appear")
    vanish = _get(r, "vanish", int, source, None, f"{where}.vanish")
    if appear < 0 or (vanish is not None and vanish <= appear):
        raise ScenarioError(source, where, f"expected 0 <= appear < vanish (ticks), got {appear}, {vanish}")
    colour = _colour(r.get("colour", fields.RESOURCE_GREY[kind]), source, f"{where}.colour")
    half = size / 2
    return Obstacle((cx - half, cy - half, cx + half, cy + half), appear, vanish, colour,
                    _get(r, "name", str, source, kind, f"{where}.name"), solid=kind != "dangerous", zone=kind,
                    reach=reach)  # fmt: skip


def _group(g, robot: RobotModel, controllers: Mapping[str, ControllerSpec], source: str, where: str) -> Group:
    if not isinstance(g, dict):
        raise ScenarioError(source, where, "expected a [[group]] table")
    no_unknown(g, set(fields.GROUP), source, f"[[group]] ({where})")
    count = _get(g, "count", int, source, 1, f"{where}.count")
    controller = _get(g, "controller", str, source, "carrot", f"{where}.controller")
    _check_controller(controller, controllers, source, f"{where}.controller")
    model = _robot(g["robot"], source, f"{where}.robot") if "robot" in g else robot
    starts = None
    if "start" in g or "starts" in g:
        raw = [g["start"]] if "start" in g else g["starts"]
        starts = tuple(
            (p[0], p[1], p[2] if len(p) > 2 else 0.0) for p in _point_list(raw, source, f"{where}.starts", (2, 3))
        )
        if len(starts) != count:
            raise ScenarioError(source, f"{where}.starts", f"expected {count} poses (one per robot), got {len(starts)}")
    goals, draw_goals = None, g.get("goals") == "drawn"  # goals = "drawn": one each, from the seed
    if not draw_goals and ("goal" in g or "goals" in g):
        raw = [g["goal"]] if "goal" in g else g["goals"]
        goals = tuple(_point_list(raw, source, f"{where}.goals", 2))
        if len(goals) not in (1, count):
            raise ScenarioError(source, f"{where}.goals", f"expected 1 or {count} goals, got {len(goals)}")
    clearance = float(_get(g, "clearance", (int, float), source, 0.04, f"{where}.clearance"))
    route = _get(g, "route", str, source, None, f"{where}.route")
    return Group(count, controller, model, starts, clearance, goals, draw_goals=draw_goals, route=route)  # type: ignore[arg-type]


# ------------------------------------------------------------------ validation


def _check_controller(name: str, controllers: Mapping[str, ControllerSpec], source: str, where: str) -> None:
    if name in controllers:
        return
    reason = f"unknown arena controller {name!r}; expected one of {', '.join(controllers)} or module:Class"
    if ":" in name:  # a user's class: why it cannot be loaded, or that it drives in another world
        try:
            controllers[name]
        except KeyError as exc:  # UnknownPart (cannot load) is a KeyError's sibling: ValueError
            reason = f"{name!r} is not an arena controller ({exc})"
        except ValueError as exc:
            reason = str(exc)
    raise ScenarioError(source, where, reason)


def check_arena(s: ArenaScenario, source: str) -> None:
    w, h = s.size
    _check_arena_settings(s, source)

    def inside(x: float, y: float) -> bool:
        return -1e-9 <= x <= w + 1e-9 and -1e-9 <= y <= h + 1e-9

    for i, wall in enumerate(s.walls):
        c = wall.coords
        if not (inside(c[0], c[1]) and inside(c[2], c[3])):
            raise ScenarioError(source, f"wall {i + 1} ({wall.name or wall.shape})",
                                f"{list(c)} is outside the arena [0, 0, {w:g}, {h:g}]")  # fmt: skip
    for i, o in enumerate(s.obstacles):
        if not (inside(o.rect[0], o.rect[1]) and inside(o.rect[2], o.rect[3])):
            raise ScenarioError(source, f"obstacle {i + 1}", f"{list(o.rect)} is outside the arena")
    for name, table in s.controller_params.items():
        try:
            s.known_controllers[name].check_table(table)
        except (ValueError, TypeError) as e:
            raise ScenarioError(source, f"[{name}]", str(e).removeprefix(f"[{name}]: ")) from None
    rects, segs = s.blocking_rects(0), s.wall_segments()
    for gi, g in enumerate(s.groups):
        m = g.robot
        if not (0.005 <= m.radius <= 5 and m.axle > 0 and m.max_wheel_speed > 0 and m.max_turn_rate > 0):
            raise ScenarioError(source, f"group {gi + 1}: robot", "expected radius 0.005-5 m and positive axle, "
                                "wheel speed and turn rate")  # fmt: skip
        if g.count < 1:
            raise ScenarioError(source, f"group {gi + 1}.count", f"expected at least 1, got {g.count}")
        missing = [k for k in s.known_controllers[g.controller].requires if k not in m.sensors]
        if missing:
            raise ScenarioError(source, f"group {gi + 1}.robot", f"{g.controller} needs the {' and '.join(missing)} "
                                f"sensor(s), which the {m.name} lacks; add them: robot = {{ model = \"{m.name}\", "
                                f"sensors = [...] }}")  # fmt: skip
        if g.route is not None and g.route not in s.routes:
            raise ScenarioError(source, f"group {gi + 1}.route", f"no route {g.route!r} in [routes]; have "
                                f"{', '.join(s.routes) or 'none'}")  # fmt: skip
        for name, points in (("starts", g.starts or ()), ("goals", g.goals or ())):
            for k, p in enumerate(points):
                if not inside(p[0], p[1]):
                    raise ScenarioError(source, f"group {gi + 1}.{name}[{k + 1}]", f"({p[0]:g}, {p[1]:g}) is "
                                        "outside the arena")  # fmt: skip
        for k, p in enumerate(g.starts or ()):
            if clearance_at(np.array([p[:2]]), rects, segs)[0] < m.radius * 0.999:
                raise ScenarioError(source, f"group {gi + 1}.starts[{k + 1}]", f"({p[0]:g}, {p[1]:g}) is inside "
                                    f"or within a body radius ({m.radius:g} m) of a wall")  # fmt: skip
    for name, route in s.routes.items():
        if len(route) < 1 or not all(inside(x, y) for x, y in route):
            raise ScenarioError(source, f"routes.{name}", "expected at least one waypoint, all inside the arena")


def _check_arena_settings(s: ArenaScenario, source: str) -> None:
    """The run-wide numbers within their ranges: seed, timing, tick limits, goal and robot count."""
    w, h = s.size
    if not 0 <= s.seed < 2**63:
        raise ScenarioError(source, "seed", f"expected 0 to 2**63-1, got {s.seed}")
    if not 0.001 <= s.control_period <= 10:
        raise ScenarioError(source, "control_period", f"expected 0.001 to 10 s, got {s.control_period}")
    if not 1 <= s.substeps <= 1000:
        raise ScenarioError(source, "substeps", f"expected 1 to 1000, got {s.substeps}")
    if not 1 <= s.checkpoint <= 1_000_000:
        raise ScenarioError(source, "checkpoint", f"expected 1 to 1000000 ticks, got {s.checkpoint}")
    if not 1 <= s.physics_strips <= 64 or (s.physics_strips > 1 and w / s.physics_strips < s.physics_halo()):
        most = max(1, min(64, int(w / s.physics_halo())))
        raise ScenarioError(source, "physics_strips", f"expected 1 to {most} (a strip at least as wide as its "
                            f"ghosts' halo, {s.physics_halo():.3g} m), got {s.physics_strips}")  # fmt: skip
    if not 1 <= s.max_ticks <= 100_000_000:
        raise ScenarioError(source, "max_ticks", f"expected 1 to 100000000, got {s.max_ticks}")
    if not 0 < s.goal_radius <= max(w, h) or s.goal_dwell < 1:
        raise ScenarioError(source, "goal_radius/goal_dwell", "expected a positive radius and dwell >= 1 tick")
    if not 1 <= s.agents <= 100_000:
        raise ScenarioError(source, "group.count", f"expected 1 to 100000 robots in all, got {s.agents}")


# --------------------------------------------------------------------- helpers


def _get(section: dict, key: str, kind, source: str, default: Any = ..., where: str | None = None):
    """The typed value of an optional field (missing: `default`, or an error when there is none)."""
    if key not in section:
        if default is ...:
            raise ScenarioError(source, where or key, "missing")
        return default
    return typed(section, key, kind, source, where)


def _table(section: dict, key: str, source: str, where: str | None = None) -> dict:
    value = section[key]
    if not isinstance(value, dict):
        raise ScenarioError(source, where or key, f"expected a [{where or key}] table")
    return value


def _list(data: dict, key: str, source: str) -> list:
    value = data.get(key, [])
    if not isinstance(value, list):
        raise ScenarioError(source, key, f"expected [[{key}]] tables")
    return value


def _is_number(v) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _numbers(section: dict, key: str, source: str, where: str, n: int) -> tuple[float, ...]:
    if key not in section:
        raise ScenarioError(source, where, f"missing: expected {n} numbers")
    v = section[key]
    if not (isinstance(v, list) and len(v) == n and all(_is_number(x) for x in v)):
        raise ScenarioError(source, where, f"expected {n} finite numbers, got {v!r}")
    return tuple(float(x) for x in v)


def _point_list(v, source: str, where: str, n) -> list[tuple[float, ...]]:
    sizes = n if isinstance(n, tuple) else (n,)
    if not isinstance(v, list) or not all(isinstance(p, list) and len(p) in sizes and all(_is_number(x) for x in p)
                                          for p in v):  # fmt: skip
        raise ScenarioError(source, where, f"expected a list of points [{', '.join(['x', 'y', 'theta'][:max(sizes)])}]"
                            f", got {v!r}")  # fmt: skip
    return [tuple(float(x) for x in p) for p in v]


def _rect(c: tuple[float, ...], source: str, where: str) -> tuple[float, float, float, float]:
    if not (c[0] < c[2] and c[1] < c[3]):
        raise ScenarioError(source, where, f"expected [x_min, y_min, x_max, y_max] with min < max, got {list(c)}")
    return (c[0], c[1], c[2], c[3])


def _colour(v, source: str, where: str) -> Colour:
    if isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= 255:
        return (v, v, v)  # a grey level
    if isinstance(v, list) and len(v) == 3 and all(isinstance(x, int) and 0 <= x <= 255 for x in v):
        return (v[0], v[1], v[2])
    raise ScenarioError(source, where, f"expected a grey level 0-255 or [r, g, b] of 0-255, got {v!r}")


def controller_params(s: ArenaScenario, agent: int) -> dict[str, Any]:
    """What robot `agent` is given before it starts (plain data, so it can
    cross the wire): the static map, its goal or route, its body, the control
    period, the noise level, and its controller's own table."""
    group, first = None, 0
    for g in s.groups:
        if agent < first + g.count:
            group = g
            break
        first += g.count
    assert group is not None, f"no agent {agent}"
    m = group.robot
    goal = s.goals()[agent]
    return {
        "map": {"size": list(s.size), "rects": s.wall_rects().tolist(), "segments": s.wall_segments().tolist()},
        "goal": None if goal is None else list(goal),
        "route": None if group.route is None else [list(p) for p in s.routes[group.route]],
        "robot": {
            "model": m.name,
            "radius": m.radius,
            "axle": m.axle,
            "max_wheel_speed": m.max_wheel_speed,
            "max_speed": m.max_speed,
            "max_turn_rate": m.max_turn_rate,
            **{
                k: v
                for cls in SENSORS.including(m.sensors.names())
                for k, v in cls.tells(getattr(m.sensors, cls.name), m).items()
            },
        },
        "control_period": s.control_period,
        "noise": s.noise.level,
        "goal_radius": s.goal_radius,
        # the scheduled obstacles, for a controller whose paper tells the robot of them (dft, case 3)
        "obstacles": [
            {"rect": list(o.rect), "appear": o.appear, "vanish": o.vanish}
            for o in s.obstacles
            if o.solid and o.zone is None
        ],
        **s.controller_params,  # every controller's table: one may drive with another's (fingerprint: carrot)
        group.controller: s.controller_params.get(group.controller, {}),
        "table": s.controller_params.get(group.controller, {}),  # its own table, whatever name it runs under
    }
