"""The scenario parser, fuzzed: random text, and the bundled scenarios with lines dropped, repeated,
swapped, cut or given odd values, or their tables mutated and written back.  Every input gives a
scenario or a one-line ScenarioError, within the time limit (tests/fuzz.py; a long run: docs/testing.md)."""

from __future__ import annotations

import json
import math
import re
import tomllib
from collections import Counter
from pathlib import Path
from typing import Any

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from swarm.core.errors import ScenarioError
from swarm.scenario import BUNDLED_DIR, parse_scenario_text
from tests.fuzz import FUZZ, guarded, mutate_tree
from world_server.arena.scenario import ArenaScenario
from world_server.grid.scenario import Scenario

FILES = sorted(BUNDLED_DIR.glob("*.toml"))
TEXTS = {path: path.read_text(encoding="utf-8") for path in FILES}
ODD_VALUES = ["-1", "0", "1", "1e309", "-1e309", "nan", "inf", "9223372036854775807", "-9223372036854775808",
              "340282366920938463463374607431768211456", '""', '"x"', '"../../../etc/passwd"', "[]", "{}", "true",
              "[1, 2]", "[[0, 0, 1e9, 1e9]]", '["a", 1]', "1e-320", "0.0", "-0.0", "4097", "100000"]  # fmt: skip
ERRORS: Counter = Counter()  # the field (`where`) of each ScenarioError


@pytest.fixture(scope="module", autouse=True)
def _report_errors():
    yield
    print(f"\nscenario errors by field ({sum(ERRORS.values())} in all):")
    print("\n".join(f"{count:8d}  {where}" for where, count in ERRORS.most_common()))


def _parse(text: str, source: Path | str) -> None:
    """A scenario, or a one-line ScenarioError, counted by the field it names."""
    try:
        with guarded():
            scenario = parse_scenario_text(text, str(source))
    except ScenarioError as exc:
        assert str(exc) and "\n" not in str(exc), repr(str(exc))
        ERRORS[re.sub(r"\d+", "N", exc.where)[:60]] += 1  # by field: `wall N.rect`
        return
    assert isinstance(scenario, Scenario | ArenaScenario)


# --------------------------------------------------------- text mutations


@st.composite
def _lines_mutated(draw) -> tuple[str, Path]:
    path = draw(st.sampled_from(FILES))
    lines = TEXTS[path].splitlines()
    for _ in range(draw(st.integers(1, 3))):
        at = draw(st.integers(0, len(lines) - 1))
        how = draw(st.sampled_from(["value", "value", "drop", "repeat", "swap", "cut", "insert"]))
        if how == "value" and "=" in lines[at]:
            key = lines[at].split("=", 1)[0]
            lines[at] = f"{key}= {draw(st.sampled_from(ODD_VALUES))}"
        elif how == "drop":
            del lines[at]
        elif how == "repeat":
            lines.insert(at, lines[at])
        elif how == "swap":
            other = draw(st.integers(0, len(lines) - 1))
            lines[at], lines[other] = lines[other], lines[at]
        elif how == "cut":
            lines[at] = lines[at][: draw(st.integers(0, len(lines[at])))]
        else:
            lines.insert(at, draw(st.text(max_size=30)))
        if not lines:
            break
    return "\n".join(lines), path


def _toml_value(value: Any) -> str:
    """`value` as TOML, inline (tables as inline tables); what TOML has no form for becomes a string."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf") if math.isinf(value) else repr(value)
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value if v is not None) + "]"
    if isinstance(value, dict):
        items = ", ".join(f"{json.dumps(str(k))} = {_toml_value(v)}" for k, v in value.items() if v is not None)
        return "{" + items + "}"
    if isinstance(value, bytes):
        value = value.hex()
    return json.dumps(str(value))


@st.composite
def _tables_mutated(draw) -> tuple[str, Path]:
    """A bundled file's tables with one to three values dropped, added or changed (odd values, other types),
    written back as TOML."""
    path = draw(st.sampled_from(FILES))
    tree = tomllib.loads(TEXTS[path])
    for _ in range(draw(st.integers(1, 3))):
        tree = draw(mutate_tree(tree))
    if not isinstance(tree, dict):
        tree = {"value": tree}
    text = "\n".join(f"{json.dumps(str(k))} = {_toml_value(v)}" for k, v in tree.items() if v is not None)
    return text, path


texts = st.one_of(st.tuples(st.text(max_size=200), st.just(FILES[0])), _lines_mutated(), _tables_mutated(),
                  _tables_mutated())  # fmt: skip


@FUZZ
@given(texts)
@example(("", FILES[0]))
@example(('kind = "arena"\nsize = [1e309, 1e309]\n', FILES[0]))
@example(('kind = ["arena"]\n', FILES[0]))
def test_scenario_texts(case):
    _parse(*case)


def test_the_bundled_scenarios_parse_and_their_tables_write_back():
    """The mutations start from scenarios the parser accepts, and the TOML writer loses nothing."""
    for path, text in TEXTS.items():
        _parse(text, path)
        tree = tomllib.loads(text)
        written = "\n".join(f"{json.dumps(k)} = {_toml_value(v)}" for k, v in tree.items())
        assert tomllib.loads(written) == tree, path.name
