"""Controllers' parameters from a scenario's table, one way for all of them."""

from __future__ import annotations

from dataclasses import fields
from typing import Any


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
    return cls(**{k: (v if k in texts else int(v) if k in ints else float(v)) for k, v in table.items()})
