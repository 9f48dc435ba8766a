"""Reading a scenario's TOML tables, one way for every part: typed fields, unknown ones refused in
one line that names the file and the field, and a parameter dataclass filled from a table."""

from __future__ import annotations

import argparse
import numbers
from dataclasses import fields
from typing import Any

from swarm.core.errors import ScenarioError


def params_from_table(cls, table: dict[str, Any] | None, section: str, ints=(), texts=(), nested=()):
    """A frozen dataclass `cls` of parameters from the scenario's [section] table.

    Unknown fields are refused in one line that names them and lists the known
    ones; `ints` are read as integers, `texts` as they are, the rest as floats;
    `nested` subtables belong to someone else and are skipped."""
    table = {k: v for k, v in (table or {}).items() if k not in nested}
    known = {f.name for f in fields(cls)}
    if unknown := sorted(set(table) - known):
        raise ValueError(f"[{section}]: unknown field {unknown[0]!r}; expected one of "
                         f"{', '.join(sorted(known | set(nested)))}")  # fmt: skip
    for k, v in table.items():
        if k not in texts and isinstance(v, bool):  # float(True) is 1.0: a switch given for a number is a slip
            raise ValueError(f"[{section}] {k}: expected a number, got {str(v).lower()}")
        if k not in texts and not isinstance(v, numbers.Real):  # "x", a list, a table: no number at all
            raise ValueError(f"[{section}] {k}: expected a number, got {v!r}")
    return cls(**{k: (v if k in texts else int(v) if k in ints else float(v)) for k, v in table.items()})


def section_of(data: dict, key: str, source: str) -> dict:
    """data[key], which must be a table."""
    value = data[key]
    if not isinstance(value, dict):
        raise ScenarioError(source, key, f"expected a [{key}] table")
    return value


def no_unknown(section: dict, allowed: set[str], source: str, where: str) -> None:
    for key in section:
        if key not in allowed:
            raise ScenarioError(
                source,
                f"{where}: {key}",
                f"unknown field; expected one of {', '.join(sorted(allowed))}",
            )


def typed(section: dict, key: str, kind, source: str, where: str | None = None):
    value = section[key]
    kinds = kind if isinstance(kind, tuple) else (kind,)
    if isinstance(value, bool) or not isinstance(value, kinds):
        names = " or ".join(k.__name__ for k in kinds)
        raise ScenarioError(source, where or key, f"expected {names}, got {value!r}")
    return value


def positive(text: str) -> int:
    """A command-line count: a positive integer."""
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text}")
    return value


def positive_number(text: str) -> float:
    """A command-line amount (minutes, seconds): a positive finite number."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text}") from None
    if not 0 < value < float("inf"):
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text}")
    return value


def seed(text: str) -> int:
    """A command-line seed: 0 to 2**63-1."""
    value = int(text)
    if not 0 <= value < 2**63:
        raise argparse.ArgumentTypeError(f"expected a seed from 0 to 2**63-1, got {text}")
    return value
