"""Every controller's parameters are declared once, each value with its provenance (swarm.core.params)."""

from __future__ import annotations

import dataclasses

import pytest

from agents.controllers import CONTROLLERS
from swarm.core.params import CODE, OURS, PAPER, SOURCES, declared, provenance, provenance_table
from swarm.core.registry import resolve

# the controllers swarm ships, whose models the reproductions hold to one declared set; a user's installed
# package (the examples) may declare its parameters or not
NAMES = [n for n in CONTROLLERS.names() if CONTROLLERS[n].factory.startswith(("agents.", "world_server."))]


@pytest.mark.parametrize("name", NAMES)
def test_each_controller_declares_its_parameter_classes(name):
    spec = CONTROLLERS[name]
    assert spec.parameters, f"{name} declares no parameter class"
    for reference in spec.parameters:
        assert dataclasses.is_dataclass(resolve(reference)), reference


@pytest.mark.parametrize("name", NAMES)
def test_every_field_has_its_provenance(name):
    for reference in CONTROLLERS[name].parameters:
        cls = resolve(reference)
        rows = provenance(cls)
        assert [p.name for p in rows] == [f.name for f in dataclasses.fields(cls)]
        for p in rows:
            where = f"{reference}.{p.name}"
            assert p.source in SOURCES, f"{where}: no provenance"
            assert p.where or p.reason, f"{where}: neither where nor reason"
            if p.source == OURS:
                assert p.reason, f"{where}: a value of ours without its reason"
            else:
                assert p.where, f"{where}: a {p.source} value without where it is given"


@pytest.mark.parametrize("name", NAMES)
def test_the_table_has_a_row_per_field(name):
    for reference in CONTROLLERS[name].parameters:
        cls = resolve(reference)
        lines = provenance_table(cls).splitlines()
        assert lines[:2] == ["| name | value | source | where / reason |", "|---|---|---|---|"]
        assert len(lines) == 2 + len(dataclasses.fields(cls))
        for line, f in zip(lines[2:], dataclasses.fields(cls), strict=True):
            assert line.startswith(f"| {f.name} | ") and line.count(" | ") >= 3


def test_declared_refuses_ours_without_a_reason():
    with pytest.raises(ValueError, match="reason"):
        declared(1.0, source=OURS)
    with pytest.raises(ValueError, match="reason"):
        declared(1.0, source=OURS, where="eq. 3", reason="  ")
    with pytest.raises(ValueError, match="where"):
        declared(1.0, source=PAPER)
    with pytest.raises(ValueError, match="source"):
        declared(1.0, source="folklore")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="reason"):

        @dataclasses.dataclass(frozen=True)
        class Bad:
            x: float = declared(1.0, source=OURS)


def test_declared_fields_keep_their_defaults_and_behaviour():
    @dataclasses.dataclass(frozen=True)
    class P:
        a: float = declared(0.95, source=PAPER, where="section 5.5")
        b: tuple[int, ...] = declared((1, 2), source=CODE, where="file.m:12")
        c: list[int] = declared([3], source=OURS, reason="a mutable default, copied per instance")

    p, q = P(), P()
    assert (p.a, p.b, p.c) == (0.95, (1, 2), [3]) and p.c is not q.c
    assert dataclasses.asdict(P(a=0.5)) == {"a": 0.5, "b": (1, 2), "c": [3]}
    rows = provenance(P)
    assert [(r.name, r.value, r.source) for r in rows] == [("a", 0.95, PAPER), ("b", (1, 2), CODE), ("c", [3], OURS)]
    table = provenance_table(P)
    assert "| a | 0.95 | paper | section 5.5 |" in table
    assert "| c | [3] | ours | a mutable default, copied per instance |" in table


def test_an_undeclared_field_shows_as_undeclared():
    @dataclasses.dataclass(frozen=True)
    class Plain:
        x: int = 3

    assert provenance(Plain)[0].source is None
    assert "| x | 3 | undeclared |" in provenance_table(Plain)
