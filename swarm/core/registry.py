"""One registry per kind of part, each entry describing itself (ARGoS registers every plugin with
its own documentation; VMAS finds scenarios by name).

A part's folder declares its entry as plain data: names, numbers and "module:attribute"
references that are imported only when asked for.  Reading a registry therefore loads no
controller, kernel or numba: an agent process can look its controller up for the price of a few
small modules.  A registry finds its entries by importing every subpackage of one package and
reading one attribute of it (an entry, or a tuple of entries), so adding a part is adding its
folder.  The registries themselves live in the layer of their parts (agents.controllers.CONTROLLERS).
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any, Generic, Protocol, TypeVar


def resolve(reference: str) -> Any:
    """The object a "package.module:attribute.attribute" reference names (imported now)."""
    module, _, attr = reference.partition(":")
    target: Any = importlib.import_module(module)
    for part in attr.split(".") if attr else ():
        target = getattr(target, part)
    return target


class UnknownPart(ValueError):
    """A name no entry of the registry has; the message lists the ones it has."""


@dataclass(frozen=True)
class ControllerSpec:
    """Everything the project needs to know of one controller, in its own folder.

    `factory`: an arena controller's class ("module:Class", made with no arguments: the face in
    agents/controllers/arena.py), or a grid controller's compiled kind code ("module:CONSTANT").
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


class Entry(Protocol):
    name: str


E = TypeVar("E", bound=Entry)


class Registry(Generic[E]):
    """The entries of one kind of part, found in the subpackages of `package` (each declares
    `attribute`: an entry or a tuple of entries), folder by folder in name order, each folder's
    entries in the order it declares them."""

    def __init__(self, what: str, package: str, attribute: str):
        self.what, self.package, self.attribute = what, package, attribute
        self._entries: dict[str, E] | None = None

    def _found(self) -> dict[str, E]:
        if self._entries is None:
            found: dict[str, E] = {}
            root = importlib.import_module(self.package)
            for info in pkgutil.iter_modules(root.__path__, f"{self.package}."):
                if not info.ispkg:
                    continue
                declared = getattr(importlib.import_module(info.name), self.attribute, ())
                for entry in declared if isinstance(declared, tuple) else (declared,):
                    if entry.name in found:
                        raise RuntimeError(f"two {self.what}s named {entry.name!r}: {info.name} and another")
                    found[entry.name] = entry
            self._entries = found
        return self._entries

    def __getitem__(self, name: str) -> E:
        entries = self._found()
        if name not in entries:
            raise UnknownPart(f"unknown {self.what} {name!r}; expected one of {', '.join(entries)}")
        return entries[name]

    def __contains__(self, name: object) -> bool:
        return name in self._found()

    def __iter__(self) -> Iterator[E]:
        return iter(self._found().values())

    def names(self, where: Callable[[E], bool] = lambda _: True) -> tuple[str, ...]:
        return tuple(e.name for e in self if where(e))
