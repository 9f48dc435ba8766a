"""One registry per kind of part, each entry describing itself (ARGoS registers every plugin with
its own documentation; VMAS finds scenarios by name).

A part's folder declares its entry as plain data: names, numbers and "module:attribute"
references that are imported only when asked for.  Reading a registry therefore loads no
controller, kernel or numba: an agent process can look its controller up for the price of a few
small modules.  A registry finds its entries by importing every subpackage of one package and
reading one attribute of it (an entry, or a tuple of entries), so adding a part is adding its
folder.  The registries themselves live in the layer of their parts (agents.controllers.CONTROLLERS,
world_server.WORLD_KINDS).
"""

from __future__ import annotations

import dataclasses
import importlib
import importlib.metadata
import pkgutil
import sys
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from typing import Any, Generic, Protocol, TypeVar

from swarm.core.errors import one_line


def resolve(reference: str) -> Any:
    """The object a "package.module:attribute.attribute" reference names (imported now)."""
    module, _, attr = reference.partition(":")
    target: Any = importlib.import_module(module)
    for part in attr.split(".") if attr else ():
        target = getattr(target, part)
    return target


class UnknownPart(ValueError):
    """A name no entry of the registry has; the message lists the ones it has."""


class Refused(ValueError):
    """An installed package's entry the registry will not take: the message says why and what to do
    (told as it is, without the exception's name)."""


@dataclass(frozen=True)
class ControllerSpec:
    """Everything the project needs to know of one controller, in its own folder.

    `factory`: an arena controller's class ("module:Class", made with no arguments: the face in
    agents/controllers/arena.py), a bundled grid controller's compiled kind code ("module:CONSTANT"),
    or a user's grid controller (world_server.grid.face.own.GridController, "module:NAME").
    `table`: a callable that raises ValueError in one line for a bad [name] table of a scenario.
    `requires`: the sensors its robot must carry.  `shares`: the key space it writes
    (swarm/<run>/<share>/<agent>), if any.  `kernels`: modules whose `exported` kernels the
    agents' ahead-of-time build must compile.  `records`: the logs an arena recording keeps of
    its record() (its map, its fields, its channels).  `parameters`: its parameter classes
    ("module:Class", each field declared with its provenance: swarm.core.params).  `example`: a
    bundled scenario it runs in
    (`swarm run EXAMPLE --controller NAME`; the tests run every controller there).  What a robot
    publishes on its share at tick t, every other robot of the same share receives before it steps
    tick t + 1."""

    name: str
    world: str  # the world kind it drives in: "grid" or "arena"
    description: str  # one line, for `swarm --help` and the docs
    factory: str
    table: str | None = None
    requires: tuple[str, ...] = ()
    shares: str | None = None
    kernels: tuple[str, ...] = ()
    records: tuple[str, ...] = ()  # "module:Class" of the logs that show what explains its choices (swarm.core.series)
    parameters: tuple[str, ...] = ()  # "module:Class" of its parameter dataclasses (swarm.core.params)
    example: str = "setup1"

    @classmethod
    def of_class(cls, name: str, reference: str) -> ControllerSpec:
        """The entry of a user's arena controller class ("module:Class"), from what the class says
        of itself: `description` (default: its docstring's first line), `requires`, `shares`,
        `check_table` (a static or class method raising ValueError for a bad table), `parameters`
        and `records` ("module:Class" references), `example`.  A grid controller is a GridController
        object instead ("module:NAME"): `of_grid`."""
        target = resolve(reference)
        if getattr(target, "world", None) == "grid" and not isinstance(target, type):
            return cls.of_grid(name, reference, target)
        if not isinstance(target, type):
            raise TypeError(f"{reference} is not a class; expected module:Class of an arena controller or "
                            "module:NAME of a grid controller (world_server.grid.face.own.GridController)")  # fmt: skip
        if getattr(target, "world", "arena") != "arena":
            raise TypeError(f"{reference} says world = {target.world!r}; a class drives in the arena (a grid "
                            "controller is a GridController object: docs/controllers.md)")  # fmt: skip
        face = ("reset", "step", "snapshot", "restore", "record")
        missing = [f"{m}()" for m in face if not callable(getattr(target, m, None))]
        if missing:
            raise TypeError(f"{reference} lacks {', '.join(missing)}: an arena controller has reset, step, "
                            "snapshot, restore and record (agents/controllers/arena.py)")  # fmt: skip
        doc = (target.__doc__ or "").strip().splitlines()
        return cls(
            name=name,
            world="arena",
            description=str(getattr(target, "description", doc[0] if doc else reference)),
            factory=reference,
            table=f"{reference}.check_table" if callable(getattr(target, "check_table", None)) else None,
            requires=tuple(getattr(target, "requires", ())),
            shares=getattr(target, "shares", None),
            records=tuple(getattr(target, "records", ())),
            parameters=tuple(getattr(target, "parameters", ())),
            example=str(getattr(target, "example", "zmaze")),
        )

    @classmethod
    def of_grid(cls, name: str, reference: str, target: Any) -> ControllerSpec:
        """The entry of a user's grid controller ("module:NAME" of a
        world_server.grid.face.own.GridController, which checked itself when made)."""
        doc = (target.description or reference).strip().splitlines()
        return cls(name=name, world="grid", description=doc[0] if doc else reference, factory=reference,
                   table=f"{reference}.check_table", example="setup2")  # fmt: skip

    @classmethod
    def of_plugin(cls, name: str, reference: str) -> ControllerSpec:
        """An installed package's entry (entry point group `swarm.controllers`): a ControllerSpec
        the package declares, or its controller class."""
        target = resolve(reference)
        if isinstance(target, ControllerSpec):  # known by the entry point's name, whatever it declares
            return target if target.name == name else dataclasses.replace(target, name=name)
        return cls.of_class(name, reference)

    def make(self) -> Any:
        """A fresh controller (arena), or the kind code of the compiled step (grid)."""
        target = resolve(self.factory)
        return target() if callable(target) else target

    def check_table(self, table: dict[str, Any]) -> None:
        """Raise ValueError (one line, naming the field) if `table` is not a valid [name] table."""
        if self.table is not None:
            resolve(self.table)(table)


@dataclass(frozen=True)
class Option:
    """A command-line option of an experiment or a benchmark, declared beside it: the command
    line offers every option some entry declares, and refuses one the chosen entry does not take.
    `type` and `collect` are "module:function" references: the first parses the text (argparse's
    type), the second turns the list of a repeated option into the value the entry is given."""

    flag: str  # "--ratios"
    help: str
    dest: str | None = None  # the keyword the entry's run is given (default: the flag's name)
    type: str | None = None
    metavar: str | None = None
    choices: tuple[str, ...] | None = None
    repeat: bool = False
    collect: str | None = None
    default: Any = None

    @property
    def keyword(self) -> str:
        return self.dest or self.flag.lstrip("-").replace("-", "_")


@dataclass(frozen=True)
class ExperimentSpec:
    """One experiment of a paper: `run` ("module:function") is called as
    run(name, reps=, jobs=, seed=, out=, **options) and returns {"markdown", "out", ...}; `writes`
    lists the files it leaves in `out`."""

    name: str
    paper: str  # the folder's paper: simonin2007, billing2015, tapus2006, girard2005
    description: str
    run: str
    options: tuple[Option, ...] = ()  # besides --reps, --jobs, --seed and --out, which every experiment takes
    writes: str = "runs.csv, summary.csv, table.md, plot.png"
    # Keywords for run() that make a run of seconds, all files written (tests run every experiment so).
    smoke: tuple[tuple[str, Any], ...] = (("reps", 1),)


@dataclass(frozen=True)
class BenchmarkSpec:
    """One benchmark: `run` ("module:function") is called as run(quick=, **options) and returns a
    JSON-able result; `report` ("module:function") turns that result into the text printed."""

    name: str
    description: str
    run: str
    report: str
    options: tuple[Option, ...] = ()


@dataclass(frozen=True)
class PaperSpec:
    """One paper we reproduce: `reproduce` ("module:function") is called as
    reproduce(quick=, jobs=, out=, progress=); it runs the paper's experiments on the confirmation
    seeds and writes one report (report.md, its plots and CSVs) into `out`, the results part of the
    model's page `page`; it returns {"markdown", "out", "claims", "verdicts"}."""

    name: str  # the folder: simonin2007, billing2015, tapus2006, girard2005
    title: str
    reproduce: str
    page: str


@dataclass(frozen=True)
class WorldKindSpec:
    """Everything the project needs to know of one world kind, declared in its folder
    (world_server/<kind>/__init__.py).

    Like an ARGoS plugin, the entry names its parts wherever they live: the world's own ones
    (its scenario section, its server) in its folder, and the parts that live above the worlds
    (the agent runtime, the engine run, the recorder, the review, the command line's options) in
    the layers that own them.  Every part is a "module:attribute" reference, imported only when
    it is used, so declaring a kind imports nothing upward and reading the registry loads no
    world (an agent process finds its runtime for the price of two small modules); the import
    graph stays one-way because the references are strings, resolved by whoever calls them.

    Called as (each "module:function"):
      parse(data, text, source, name, controllers) -> scenario: its section of a scenario file
          (`data`: the TOML tables, `name`: the default name, `controllers`: the registry's
          controllers of this kind, by name);
      server: the WorldKind class the world process's server holds (world_server.server.WorldKind);
      runtime(run_id, controller, connect, count, **options) -> an agent process's runtime;
      open_recorder(server, path, viewer) and goals(scenario): what the world process
          is lent (world_server.server.RunnerServices);
      run(scenario, args, viewer) -> summary: `swarm run`, in one process (recorded with --record);
      warm_up(scenario, engine): compile what its runs need (`swarm prepare`, `swarm up`);
      review(recording) -> summary and plots(recording, folder) -> files: `swarm report`;
      options(parser): its command-line options; overrides(scenario, args, common) -> scenario:
          their values (with `common`: agents, controller, seed); check(scenario, until): a run
          the command line refuses before it starts; up_options(scenario, args) -> keywords of
          swarm.launcher.swarm_up; print_summary(summary, as_json, until) -> exit status;
      commands: functions that add a subcommand to `swarm` (add(subparsers) -> (name, handler))."""

    name: str  # the scenario file's `kind`
    description: str  # one line
    example: str  # a bundled scenario or preset of this kind: `swarm prepare` warms it up, the tests run it
    parse: str
    server: str
    runtime: str
    run: str
    warm_up: str
    review: str
    plots: str
    print_summary: str
    overrides: str
    up_options: str
    # (done, total): the keys of its progress and summary that count the run's progress (the status
    # line "delivered 3/10", the progress bars); a recording's series `done` has one value per tick.
    progress: tuple[str, str]
    metrics: str  # "module:NAME": the names of the scalar series its recording keeps
    default: bool = False  # the kind of a scenario file, a summary or a recording that names none
    open_recorder: str | None = None
    goals: str | None = None
    options: str | None = None
    options_title: str | None = None  # its options' own section of --help (None: among the command's own)
    check: str | None = None
    commands: tuple[str, ...] = ()
    # "module:function": schema(controllers, installed) -> the JSON Schema of its scenario files (with
    # `installed` False, without the parts of installed packages)
    schema: str | None = None


class Entry(Protocol):
    name: str


E = TypeVar("E", bound=Entry)


class Registry(Generic[E]):
    """The entries of one kind of part, found in the subpackages of `package` (each declares
    `attribute`: an entry or a tuple of entries), folder by folder in name order, each folder's
    entries in the order it declares them.  With `modules`, a plain module of `package` may
    declare entries too (one module per part); with `key`, the entries are in its order instead
    (a part that declares its own place: the arena's sensors).

    Parts from outside the package: with `plugins` (an entry point group), every installed
    package's entry point of that group is an entry, made by `external(name, "module:attribute")`;
    with `external`, a name that is itself a "module:attribute" reference is one too (made when
    first asked for, then kept).  An entry point's module is imported only when its entry is asked
    for (by name, or by going through every entry): its name alone (`names()`, the command line's
    help) is read from the installed packages' metadata."""

    def __init__(self, what: str, package: str, attribute: str, *, modules: bool = False,
                 key: Callable[[E], Any] | None = None, plugins: str | None = None,
                 external: Callable[[str, str], E] | None = None, references: bool = True):  # fmt: skip
        self.what, self.package, self.attribute = what, package, attribute
        self.modules, self.key = modules, key
        self.plugins, self.external = plugins, external
        self.references = references and external is not None  # a "module:attribute" name is an entry
        self._entries: dict[str, E] | None = None  # the package's own
        self._points: dict[str, str] | None = None  # the installed packages' entry points: name -> "module:attribute"
        self._made: dict[str, E | None] = {}  # the entry points made so far (None: left out)
        self._loaded: dict[str, E] = {}  # "module:attribute" names made so far

    def _found(self) -> dict[str, E]:
        if self._entries is None:
            found: dict[str, E] = {}
            root = importlib.import_module(self.package)
            for info in pkgutil.iter_modules(root.__path__, f"{self.package}."):
                if not (info.ispkg or self.modules):
                    continue
                declared = getattr(importlib.import_module(info.name), self.attribute, ())
                for entry in declared if isinstance(declared, tuple) else (declared,):
                    if entry.name in found:
                        raise RuntimeError(f"two {self.what}s named {entry.name!r}: {info.name} and another")
                    found[entry.name] = entry
            if self.key is not None:
                found = {e.name: e for e in sorted(found.values(), key=self.key)}
            self._entries = found
        return self._entries

    def _installed(self) -> dict[str, str]:
        """The entry points installed packages declare, by name, read from their metadata (nothing
        imported).  One whose name is taken is left out with one line on stderr."""
        if self._points is None:
            self._points = {}
            if self.plugins is not None and self.external is not None:
                found = self._found()
                for point in importlib.metadata.entry_points(group=self.plugins):
                    if point.name in found or point.name in self._points:
                        print(f"swarm: {self.what} {point.name!r} of {point.value} left out: the name is taken; "
                              "give the entry point another name", file=sys.stderr)  # fmt: skip
                        continue
                    self._points[point.name] = point.value
        return self._points

    @property
    def installed(self) -> set[str]:
        """The names installed packages' entry points give (whether or not they load)."""
        return set(self._installed())

    def _made_of(self, name: str) -> E | None:
        """The entry of installed entry point `name`, made once.  One that cannot be made is left out
        with one line on stderr (a broken plugin must not stop every command): None."""
        if name not in self._made:
            reference = self._installed()[name]
            try:
                self._made[name] = self.external(name, reference)  # type: ignore[misc]
            except Refused as exc:
                self._made[name] = None
                print(f"swarm: {self.what} {name!r} ({reference}) refused: {exc}", file=sys.stderr)
            except Exception as exc:  # whatever a user's package raises on import
                self._made[name] = None
                print(f"swarm: {self.what} {name!r} ({reference}) left out: {one_line(exc)}", file=sys.stderr)
        return self._made[name]

    def _ordered(self, names: Iterator[str] | tuple[str, ...] | list[str] | set[str]) -> dict[str, E]:
        """The package's entries and the installed ones among `names` (made now), in the registry's order."""
        found = dict(self._found())
        points = self._installed()
        for name in [n for n in points if n in set(names)]:
            if (entry := self._made_of(name)) is not None:
                found[name] = entry
        if self.key is not None and len(found) > len(self._found()):
            found = {e.name: e for e in sorted(found.values(), key=self.key)}
        return found

    def _all(self) -> dict[str, E]:
        return self._ordered(tuple(self._installed()))

    def known(self) -> dict[str, E]:
        """The package's entries and the installed ones made so far (nothing imported)."""
        return self._ordered([n for n, e in self._made.items() if e is not None])

    def including(self, names: Any) -> tuple[E, ...]:
        """The package's entries and the installed ones among `names` (imported now), in order."""
        return tuple(self._ordered([n for n in names if isinstance(n, str)]).values())

    def load(self, reference: str) -> E:
        """The entry of a "module:attribute" name (`external`), made once; UnknownPart in one line
        saying why it cannot be."""
        if reference not in self._loaded:
            if not self.references or ":" not in reference:
                raise UnknownPart(f"unknown {self.what} {reference!r}; expected one of {', '.join(self.names())}")
            try:
                self._loaded[reference] = self.external(reference, reference)
            except ModuleNotFoundError as exc:
                raise UnknownPart(f"cannot load {self.what} {reference!r}: {one_line(exc)}; install its package "
                                  "or put its folder on PYTHONPATH") from None  # fmt: skip
            except Exception as exc:  # whatever a user's module raises on import
                raise UnknownPart(f"cannot load {self.what} {reference!r}: {one_line(exc)}") from None
        return self._loaded[reference]

    def __getitem__(self, name: str) -> E:
        entries = self._found()
        if isinstance(name, str) and name in entries:
            return entries[name]
        if isinstance(name, str) and name in self._installed() and (entry := self._made_of(name)) is not None:
            return entry
        if isinstance(name, str) and ":" in name and self.references:
            return self.load(name)
        raise UnknownPart(f"unknown {self.what} {name!r}; expected one of {', '.join(self.names())}"
                          + (" or module:Class" if self.references else ""))  # fmt: skip

    def __contains__(self, name: object) -> bool:
        if name in self._found():
            return True
        if isinstance(name, str) and name in self._installed():
            return self._made_of(name) is not None
        try:
            return isinstance(name, str) and ":" in name and self.references and bool(self.load(name))
        except UnknownPart:
            return False

    def __iter__(self) -> Iterator[E]:
        return iter(self._all().values())

    def names(self, where: Callable[[E], bool] | None = None) -> tuple[str, ...]:
        """The entries' names.  Without `where`, the installed ones are named from their metadata,
        unimported (one that then fails to load is left out from then on)."""
        if where is None:
            made = self._made
            return (*self._found(), *(n for n in self._installed() if made.get(n, True) is not None))
        return tuple(e.name for e in self if where(e))

    def where(self, field: str, value: Any) -> Selection[E]:
        """The entries whose `field` is `value`, "module:attribute" names included (a scenario's
        controllers: those of its world kind)."""
        return Selection(self, field, value)


class Selection(Mapping[str, E]):
    """Some entries of a registry by name (Registry.where): iterating gives the registered ones and
    the loaded "module:attribute" ones; looking a reference up loads it."""

    def __init__(self, registry: Registry[E], field: str, value: Any):
        self.registry, self.field, self.value = registry, field, value

    def _fits(self, entry: E) -> bool:
        return getattr(entry, self.field) == self.value

    def __getitem__(self, name: str) -> E:
        entry = self.registry[name]
        if not self._fits(entry):
            raise KeyError(name)
        return entry

    def __contains__(self, name: object) -> bool:
        return name in self.registry and self._fits(self.registry[name])  # type: ignore[index]

    def __iter__(self) -> Iterator[str]:
        yield from (e.name for e in self.registry if self._fits(e))
        yield from (name for name, e in self.registry._loaded.items() if self._fits(e))

    def __len__(self) -> int:
        return sum(1 for _ in self)
