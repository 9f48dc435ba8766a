"""Declared parameters: every value of a model with where it comes from.

A model's parameters live on its frozen dataclasses, in one file per model: its `params.py`, which
imports nothing else of the model (a controller of one module keeps them beside its code).  Each field is
declared with `declared(default, source=..., where=..., reason=...)`, which is
`dataclasses.field(default=default, metadata={"provenance": Provenance(...)})`: defaults,
`asdict`, `replace`, equality and the tables' parsers (swarm.core.tables) see an ordinary field.
The source is one of three: PAPER (the paper gives that number; `where` cites the equation, table
or section), CODE (the original authors' code gives it; `where` names the file, or the section of
the notes we took from it) or OURS (neither does; `reason` says why this value, and declaring an
OURS value without a reason raises at import).  Constants that compiled (numba) kernels read stay
plain numbers in their modules: their provenance is declared on a dataclass of the model's, from
whose defaults the module constants are taken, or which only records the numbers a kernel writes as literals.
`provenance(cls)` lists a class's fields with their values and sources, `provenance_table(cls)`
renders them as a markdown table, and each controller's entry names its parameter classes
(swarm.core.registry.ControllerSpec.parameters), so tests/test_params.py can hold every model to
it.  An experiment then sets only what the paper says that experiment changes.
"""

from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass
from typing import Any, Final, Literal

Source = Literal["paper", "code", "ours"]
PAPER: Final = "paper"
CODE: Final = "code"
OURS: Final = "ours"
SOURCES: tuple[Source, ...] = (PAPER, CODE, OURS)
KEY: Final = "provenance"


@dataclass(frozen=True)
class Provenance:
    """Where one value comes from: `where` the paper's equation/section or the original file; `reason` why ours."""

    source: Source
    where: str = ""
    reason: str = ""


@dataclass(frozen=True)
class Parameter:
    """One field of a parameter class, as `provenance` lists it (`source` None: not declared)."""

    name: str
    value: Any
    source: Source | None
    where: str
    reason: str


def declared(
    default: Any = dataclasses.MISSING,
    *,
    source: Source,
    where: str = "",
    reason: str = "",
    default_factory: Any = dataclasses.MISSING,
) -> Any:
    """A dataclass field whose default carries its provenance.  PAPER and CODE need `where`, OURS a
    `reason`; a mutable default (list, dict, set, array) is given through a factory of copies."""
    if source not in SOURCES:
        raise ValueError(f"source {source!r}: expected one of {', '.join(SOURCES)}")
    if source == OURS and not reason.strip():
        raise ValueError("a value of ours needs its reason")
    if source != OURS and not where.strip():
        raise ValueError(f"a value from the {source} needs where it is given")
    meta = {KEY: Provenance(source, where.strip(), reason.strip())}
    if default_factory is not dataclasses.MISSING:
        return dataclasses.field(default_factory=default_factory, metadata=meta)
    if default is dataclasses.MISSING:
        raise ValueError("declared() needs a default or a default_factory")
    if getattr(type(default), "__hash__", None) is None:  # what dataclasses refuses as a default
        return dataclasses.field(default_factory=lambda: copy.deepcopy(default), metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


def provenance(cls: type) -> list[Parameter]:
    """Every field of the dataclass `cls`, in order, with its default and its declared provenance."""
    out = []
    for f in dataclasses.fields(cls):
        if f.default is not dataclasses.MISSING:
            value = f.default
        elif f.default_factory is not dataclasses.MISSING:
            value = f.default_factory()
        else:
            value = None
        p = f.metadata.get(KEY)
        if p is None:
            out.append(Parameter(f.name, value, None, "", ""))
        else:
            out.append(Parameter(f.name, value, p.source, p.where, p.reason))
    return out


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def provenance_table(cls: type) -> str:
    """A markdown table of `cls`'s parameters: name, value, source, where / reason."""
    rows = ["| name | value | source | where / reason |", "|---|---|---|---|"]
    for p in provenance(cls):
        note = "; ".join(t for t in (p.where, p.reason) if t)
        rows.append(f"| {p.name} | {_cell(repr(p.value))} | {p.source or 'undeclared'} | {_cell(note)} |")
    return "\n".join(rows)
