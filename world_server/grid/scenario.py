"""Grid scenarios: what world the swarm forages in, and who forages.

A scenario is a TOML file or a built-in preset.  It holds either an ASCII map
(`#` obstacle, `.` free, `B` base, `R` resource) or a generator (width,
height, obstacle density, number of resources), plus the quantity per
resource, the carrying capacity q_max, the agent count, the controller and
the seed.  Generated maps depend only on the seed.  Resources are placed only
on cells the base can reach (an unreachable resource could never be foraged,
so `--until foraged` could never finish); an ASCII map with an unreachable
resource is rejected.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from swarm.core.errors import ScenarioError
from swarm.core.tables import no_unknown, section_of, typed
from world_server.grid.face.layout import CONTROLLERS
from world_server.grid.face.own import own_controller
from world_server.grid.params import AntParams, CMarkingParams, PhysicsParams

CONTROLLER_NAMES = tuple(CONTROLLERS)  # the grid face's compiled controllers
DEFAULT_CONTROLLER = "cmarking"
MARKLESS = ("ant",)  # controllers that write no marks: a run of theirs cannot end "converged"
MAX_AGENTS = (1 << 20) - 2  # trail ids reserve 20 bits for the agent id
MAP_STREAM = 0x4D4150  # keeps map draws apart from any other use of the seed
MAX_MAP_DRAWS = 200
MIN_BASE_SHARE = 0.5
MAP_CHARS = "#.BR"


@dataclass(frozen=True)
class Generator:
    width: int
    height: int
    obstacle_density: float
    resources: int


RETURN_ON_TRAIL = ("mend", "descend")
AT_BASE = ("remember", "forget")


PHYSICS_MODES = ("ideal", "physical")


@dataclass(frozen=True)
class Layout:
    """A concrete world: obstacles, resource quantities, base, BFS distances."""

    obstacles: np.ndarray  # bool (H, W)
    resources: np.ndarray  # int64 (H, W), units per cell
    base: tuple[int, int]
    bfs: np.ndarray  # int64 (H, W), -1 where unreachable

    @property
    def shape(self) -> tuple[int, int]:
        return self.obstacles.shape

    @property
    def reachable_cells(self) -> int:
        return int((self.bfs >= 0).sum())


@dataclass(frozen=True)
class Scenario:
    name: str
    source: str
    seed: int = 0
    agents: int = 10
    controller: str = DEFAULT_CONTROLLER
    q_max: int = 100
    quantity: int = 1000
    ascii_map: tuple[str, ...] | None = None
    generator: Generator | None = None
    ant: AntParams = field(default_factory=AntParams)
    cmarking: CMarkingParams = field(default_factory=CMarkingParams)
    physics: PhysicsParams = field(default_factory=PhysicsParams)
    map_first_line: int = 0  # file line of the first map row, for messages
    # The grid controllers the scenario may name besides the bundled ones (a user's "module:NAME" or an
    # installed package's, world_server.grid.face.own), from the controller registry (the scenario loader's),
    # and their tables by controller name (the step's `params`).
    known_controllers: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)
    tables: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)

    def with_overrides(
        self,
        agents: int | None = None,
        controller: str | None = None,
        seed: int | None = None,
        physics: str | None = None,
        body_diameter: float | None = None,
    ) -> Scenario:
        body = self.physics
        if physics is not None:
            body = replace(body, mode=physics)
        if body_diameter is not None:
            body = replace(body, diameter=body_diameter)
        new = replace(
            self,
            agents=self.agents if agents is None else agents,
            controller=self.controller if controller is None else controller,
            seed=self.seed if seed is None else seed,
            physics=body,
        )
        _check_run_fields(new, "command line")
        _check_physics(new.physics, "command line")
        return new

    def agent_processes(self, agents: int) -> list[tuple[str, int]]:
        """(controller, robots) for every kind of agent process a run of `agents` robots needs."""
        return [(self.controller, agents)]

    def layout(self) -> Layout:
        if self.ascii_map is not None:
            return _layout_from_ascii(self)
        assert self.generator is not None
        return generate_layout(self.generator, self.quantity, self.seed, self.source)

    def describe(self) -> dict[str, Any]:
        d: dict[str, Any] = {
            "name": self.name,
            "seed": self.seed,
            "agents": self.agents,
            "controller": self.controller,
            "q_max": self.q_max,
            "quantity": self.quantity,
        }
        if self.tables:
            d["tables"] = {name: dict(table) for name, table in self.tables.items()}
        if self.generator is not None:
            g = self.generator
            d["generator"] = {
                "width": g.width,
                "height": g.height,
                "obstacle_density": g.obstacle_density,
                "resources": g.resources,
            }
        else:
            d["map"] = "\n".join(self.ascii_map or ())
        d["physics"] = asdict(self.physics)
        return d


# --------------------------------------------------------------------- presets


def paper_setup(number: int, size: int | None = None) -> Scenario:
    """The paper's setups (section 4.5, 5.3, 5.4).  Setup 2 does not state
    q_max; we use the 100 units of setups 1 and 3 (docs/cmarking.md)."""
    if number == 1:
        gen = Generator(40, 40, 0.30, 20)
        return Scenario("setup1", "preset setup1", agents=10, quantity=1000, generator=gen)
    if number == 2:
        gen = Generator(20, 20, 0.05, 2)
        return Scenario("setup2", "preset setup2", agents=1, quantity=1000, generator=gen)
    if number == 3:
        if size is None:
            raise ScenarioError("preset setup3", "size", "give a size, e.g. setup3-50")
        gen = Generator(size, size, 0.05, 20)
        name = f"setup3-{size}"
        return Scenario(name, f"preset {name}", agents=50, quantity=2000, generator=gen)
    raise ScenarioError(f"preset setup{number}", "name", "the paper defines setups 1, 2 and 3")


# --------------------------------------------------------------------- parsing

_TOP_KEYS = {"name", "seed", "agents", "controller", "q_max", "quantity", "map", "generator"}
_TOP_KEYS |= {"ant", "cmarking", "physics"}
_CMARKING_TEXTS = ("return_on_trail", "at_base")
GENERATOR_KEYS = {"width", "height", "obstacle_density", "resources"}


def parse_section(data: dict, text: str, source: str, name: str, controllers: Mapping) -> Scenario:
    """The kind's scenario parser (world_server.WORLD_KINDS): the grid Scenario of a file's tables,
    named `name` unless the file says."""
    data.pop("kind", None)
    return parse_grid(data, text, source, name, controllers)


def parse_grid(data: dict, text: str, source: str, name: str | None = None, controllers: Mapping = {}) -> Scenario:
    """The grid Scenario of a scenario file's tables (`text` only to point at the map's lines),
    named `name` (default: the file's stem) unless the file says.  `controllers`: the grid
    controllers of the registry (a user's named "module:NAME" too); a table named after one that is
    not bundled is its table."""
    own = [k for k in data if k not in _TOP_KEYS and k in controllers and k not in CONTROLLER_NAMES]
    no_unknown({k: v for k, v in data.items() if k not in own}, _TOP_KEYS, source, "top level")
    has_map, has_gen = "map" in data, "generator" in data
    if has_map == has_gen:
        raise ScenarioError(source, "map/generator", "give exactly one of [map] (ascii = ...) or [generator]")
    kw: dict[str, Any] = {"name": name or Path(source).stem, "source": source}
    if "name" in data:
        kw["name"] = typed(data, "name", str, source)
    for key in ("seed", "agents", "q_max", "quantity"):
        if key in data:
            kw[key] = typed(data, key, int, source)
    if "controller" in data:
        kw["controller"] = typed(data, "controller", str, source)
    if has_map:
        _parse_map(data, text, source, kw)
    else:
        kw["generator"] = _parse_generator(data, source)
    if "ant" in data:
        section = section_of(data, "ant", source)
        no_unknown(section, set(AntParams.__dataclass_fields__), source, "[ant]")
        kw["ant"] = AntParams(**{k: float(typed(section, k, (int, float), source, f"ant.{k}")) for k in section})
    if "cmarking" in data:
        section = section_of(data, "cmarking", source)
        no_unknown(section, set(CMarkingParams.__dataclass_fields__), source, "[cmarking]")
        kw["cmarking"] = CMarkingParams(**{k: typed(section, k, str if k in _CMARKING_TEXTS else int, source,
                                                     f"cmarking.{k}") for k in section})  # fmt: skip
    if "physics" in data:
        section = section_of(data, "physics", source)
        no_unknown(section, set(PhysicsParams.__dataclass_fields__), source, "[physics]")
        kw["physics"] = PhysicsParams(**{
            k: typed(section, k, str, source, "physics.mode") if k == "mode"
            else float(typed(section, k, (int, float), source, f"physics.{k}"))
            for k in section
        })  # fmt: skip
    kw["tables"] = {k: section_of(data, k, source) for k in own}
    scenario = Scenario(**kw, known_controllers=controllers)
    check_scenario(scenario)
    return scenario


def _parse_map(data: dict, text: str, source: str, kw: dict[str, Any]) -> None:
    """The [map] table into `kw`: the ascii map without its blank edge lines, and the file line it starts on."""
    section = section_of(data, "map", source)
    no_unknown(section, {"ascii"}, source, "[map]")
    if "ascii" not in section:
        raise ScenarioError(source, "map.ascii", "missing: a multi-line string of # . B R")
    rows = typed(section, "ascii", str, source, "map.ascii")
    lines = [ln.rstrip() for ln in rows.splitlines()]
    while lines and not lines[0]:
        lines.pop(0)
    while lines and not lines[-1]:
        lines.pop()
    kw["ascii_map"] = tuple(lines)
    kw["map_first_line"] = _first_map_line(text, lines)


def _parse_generator(data: dict, source: str) -> Generator:
    """The [generator] table, every key required."""
    section = section_of(data, "generator", source)
    keys = GENERATOR_KEYS
    no_unknown(section, keys, source, "[generator]")
    for key in sorted(keys):
        if key not in section:
            raise ScenarioError(source, f"generator.{key}", "missing")
    return Generator(
        width=typed(section, "width", int, source, "generator.width"),
        height=typed(section, "height", int, source, "generator.height"),
        obstacle_density=float(typed(section, "obstacle_density", (int, float), source, "generator.obstacle_density")),
        resources=typed(section, "resources", int, source, "generator.resources"),
    )


def _first_map_line(text: str, lines: list[str]) -> int:
    if not lines:
        return 0
    src = text.splitlines()
    start = next((i for i, ln in enumerate(src) if re.match(r"\s*ascii\s*=", ln)), 0)
    for i in range(start, len(src)):
        if src[i].rstrip().endswith(lines[0]) and lines[0]:
            return i + 1
    return 0


# ------------------------------------------------------------------ validation


def _check_run_fields(s: Scenario, source: str) -> None:
    _check_controller(s, source)
    if not 1 <= s.agents <= MAX_AGENTS:
        raise ScenarioError(source, "agents", f"expected 1 to {MAX_AGENTS}, got {s.agents}")
    if not 0 <= s.seed < 2**63:
        raise ScenarioError(source, "seed", f"expected 0 to 2**63-1, got {s.seed}")


def _check_controller(s: Scenario, source: str) -> None:
    """A bundled controller, or a user's grid controller the registry loads, whose tables are valid."""
    if s.controller not in CONTROLLER_NAMES:
        try:
            s.known_controllers[s.controller]
        except (KeyError, ValueError) as exc:  # a "module:NAME" that cannot load: the registry says why in one line
            known = ", ".join(dict.fromkeys((*CONTROLLER_NAMES, *s.known_controllers)))
            reason = f"unknown {s.controller!r}; expected one of {known} or module:NAME"
            if ":" in s.controller:  # it loaded, or the registry says why not
                reason = (str(exc) if isinstance(exc, ValueError) else f"{s.controller} is not a grid controller "
                          "(a grid scenario needs a GridController, world_server.grid.face.own; an arena "
                          "controller runs on an arena floor)")  # fmt: skip
            raise ScenarioError(source, "controller", reason) from None
    for name, table in s.tables.items():
        try:
            s.known_controllers[name].check_table(dict(table))
        except ValueError as exc:
            raise ScenarioError(source, f"[{name}]", str(exc)) from None


def _check_physics(p: PhysicsParams, src: str) -> None:
    if p.mode not in PHYSICS_MODES:
        raise ScenarioError(src, "physics.mode", f"unknown {p.mode!r}; expected one of {', '.join(PHYSICS_MODES)}")
    values = (p.diameter, p.speed, p.timeout, p.dt, p.arrive)
    if not all(np.isfinite(v) for v in values):
        raise ScenarioError(src, "physics", "expected finite numbers")
    if not 0.05 <= p.diameter < 1.0:
        raise ScenarioError(src, "physics.diameter", f"expected 0.05 to <1 cell (a body must fit a corridor), "
                            f"got {p.diameter}")  # fmt: skip
    if not 0 < p.speed <= 100:
        raise ScenarioError(src, "physics.speed", f"expected 0 to 100 cells per second, got {p.speed}")
    if not 0 < p.dt <= 0.5:
        raise ScenarioError(src, "physics.dt", f"expected a step of 0 to 0.5 s, got {p.dt}")
    if not (p.timeout * p.speed >= 1.0 and p.timeout / p.dt <= 10_000):
        raise ScenarioError(src, "physics.timeout", f"expected at least the time to cross one cell "
                            f"({1 / p.speed:g} s) and at most 10000 steps of dt, got {p.timeout}")  # fmt: skip
    if not 0 < p.arrive < 0.5:
        raise ScenarioError(src, "physics.arrive", f"expected 0 to <0.5 cell, got {p.arrive}")


def check_scenario(s: Scenario) -> None:
    src = s.source
    _check_run_fields(s, src)
    if s.q_max < 1:
        raise ScenarioError(src, "q_max", f"expected a carrying capacity >= 1, got {s.q_max}")
    if not 1 <= s.quantity <= 2**40:
        raise ScenarioError(src, "quantity", f"expected 1 to 2**40 units per resource, got {s.quantity}")
    a = s.ant
    if not 0.0 <= a.diffusion <= 1.0:
        raise ScenarioError(src, "ant.diffusion", f"expected a rate in [0, 1], got {a.diffusion}")
    if not 0.0 <= a.evaporation <= 1.0:
        raise ScenarioError(src, "ant.evaporation", f"expected a rate in [0, 1], got {a.evaporation}")
    if not (a.deposit > 0 and np.isfinite(a.deposit)):
        raise ScenarioError(src, "ant.deposit", f"expected a positive amount, got {a.deposit}")
    if not (a.threshold >= 0 and np.isfinite(a.threshold)):
        raise ScenarioError(src, "ant.threshold", f"expected an amount >= 0, got {a.threshold}")
    if not (a.ceiling > a.threshold and np.isfinite(a.ceiling)):
        raise ScenarioError(src, "ant.ceiling", f"expected an amount above threshold ({a.threshold}), got {a.ceiling}")
    if not (0 <= a.wiggle <= 180 and a.wiggle == int(a.wiggle)):
        raise ScenarioError(src, "ant.wiggle", f"expected whole degrees from 0 to 180, got {a.wiggle}")
    if not 0 <= a.detour <= 10_000:
        raise ScenarioError(src, "ant.detour", f"expected 0 to 10000 steps, got {a.detour}")
    _check_physics(s.physics, src)
    if s.cmarking.climb_patience < 1:
        raise ScenarioError(src, "cmarking.climb_patience", "expected a step count >= 1")
    if s.cmarking.return_on_trail not in RETURN_ON_TRAIL:
        raise ScenarioError(src, "cmarking.return_on_trail", f"expected one of {', '.join(RETURN_ON_TRAIL)}, "
                            f"got {s.cmarking.return_on_trail!r}")  # fmt: skip
    if s.cmarking.at_base not in AT_BASE:
        raise ScenarioError(
            src, "cmarking.at_base", f"expected one of {', '.join(AT_BASE)}, got {s.cmarking.at_base!r}"
        )
    if s.generator is not None:
        g = s.generator
        for key, value in (("width", g.width), ("height", g.height)):
            if not 3 <= value <= 4096:
                raise ScenarioError(src, f"generator.{key}", f"expected 3 to 4096 cells, got {value}")
        if not 0.0 <= g.obstacle_density <= 0.6:
            raise ScenarioError(src, "generator.obstacle_density", f"expected 0 to 0.6, got {g.obstacle_density}")
        if not 0 <= g.resources <= g.width * g.height // 2:
            raise ScenarioError(src, "generator.resources", f"expected 0 to half the cells, got {g.resources}")
    else:
        _check_ascii(s)


def _map_where(s: Scenario, row: int) -> str:
    where = f"map row {row + 1}"
    if s.map_first_line:
        where += f" (line {s.map_first_line + row})"
    return where


def _check_ascii(s: Scenario) -> None:
    rows = s.ascii_map or ()
    if not rows:
        raise ScenarioError(s.source, "map.ascii", "the map is empty; draw it with # . B R")
    width = len(rows[0])
    bases = []
    for i, row in enumerate(rows):
        if len(row) != width:
            raise ScenarioError(s.source, _map_where(s, i), f"has {len(row)} cells, expected {width} like row 1")
        for j, ch in enumerate(row):
            if ch not in MAP_CHARS:
                raise ScenarioError(
                    s.source,
                    _map_where(s, i),
                    f"column {j + 1}: unexpected {ch!r}; use # obstacle . free B base R resource",
                )
            if ch == "B":
                bases.append((i, j))
    if len(bases) != 1:
        raise ScenarioError(s.source, "map.ascii", f"expected exactly one base B, found {len(bases)}")


def _layout_from_ascii(s: Scenario) -> Layout:
    rows = s.ascii_map or ()
    grid = np.array([list(r) for r in rows])
    obstacles = grid == "#"
    base_r, base_c = (int(v[0]) for v in np.nonzero(grid == "B"))
    from world_server.grid.wavefront import bfs_distances

    bfs = bfs_distances(obstacles, base_r, base_c)
    resources = np.where(grid == "R", s.quantity, 0).astype(np.int64)
    unreachable = np.argwhere((grid == "R") & (bfs < 0))
    if len(unreachable):
        r, c = (int(v) for v in unreachable[0])
        raise ScenarioError(
            s.source,
            _map_where(s, r),
            f"column {c + 1}: resource R cannot be reached from the base; open a path or remove it",
        )
    return Layout(obstacles, resources, (base_r, base_c), bfs)


def generate_layout(g: Generator, quantity: int, seed: int, source: str = "generator") -> Layout:
    """Random obstacles at the given density (exact count), base at the centre,
    resources on distinct cells reachable from the base.  A draw whose base is
    walled into a pocket holding less than half the free cells (or fewer cells
    than resources) is redrawn from the same seed's stream."""
    from world_server.grid.wavefront import bfs_distances

    rng = np.random.default_rng([seed, MAP_STREAM])
    h, w = g.height, g.width
    base = (h // 2, w // 2)
    base_index = base[0] * w + base[1]
    n_obstacles = round(g.obstacle_density * (h * w - 1))
    free_total = h * w - n_obstacles
    for _ in range(MAX_MAP_DRAWS):
        picks = rng.choice(h * w - 1, size=n_obstacles, replace=False)
        picks[picks >= base_index] += 1  # never the base
        obstacles = np.zeros(h * w, dtype=bool)
        obstacles[picks] = True
        obstacles = obstacles.reshape(h, w)
        bfs = bfs_distances(obstacles, base[0], base[1])
        reachable = np.flatnonzero(bfs.ravel() > 0)
        if len(reachable) >= g.resources and len(reachable) + 1 >= MIN_BASE_SHARE * free_total:
            break
    else:
        raise ScenarioError(
            source,
            "generator.obstacle_density",
            f"no map in {MAX_MAP_DRAWS} draws lets the base reach half the free cells; lower the density",
        )
    resources = np.zeros(h * w, dtype=np.int64)
    resources[rng.choice(reachable, size=g.resources, replace=False)] = quantity
    return Layout(obstacles, resources.reshape(h, w), base, bfs)


def check_until(scenario: Scenario, until: str) -> None:
    """A run's end rule must fit its controller: marks converge only where robots write them."""
    if until != "foraged" and scenario.controller in MARKLESS:
        raise ScenarioError("command line", "until", "ants build no marks; only --until foraged applies to them")
    own = own_controller(scenario)
    if until != "foraged" and own is not None and not own.marks:
        raise ScenarioError("command line", "until", f"{scenario.controller} writes no marks (its marks = False); "
                            "only --until foraged applies to it")  # fmt: skip
