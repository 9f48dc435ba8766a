"""Scenario files for editors and by eye: the JSON Schema made from the parsers' tables accepts every
bundled scenario and refuses what the parser refuses for spelling and types; `swarm check` judges a
file in one line and draws its floor."""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib
from pathlib import Path

import jsonschema
import pytest

from swarm.scenario import BUNDLED_DIR, scenario_schema

ROOT = Path(__file__).parents[1]
SCENARIOS = [*sorted(BUNDLED_DIR.glob("*.toml")), ROOT / "examples" / "flocking" / "flock.toml"]


@pytest.fixture(scope="module")
def validator():
    return jsonschema.Draft202012Validator(scenario_schema())


def test_the_schema_file_is_the_one_the_registries_make():
    """swarm/scenarios/scenario.schema.json is what `swarm schema` prints (regenerate it with
    `swarm schema --package-only --out swarm/scenarios/scenario.schema.json` after adding a field or a
    part); the controllers of installed packages (the example's `flocking`) are not in it."""
    kept = json.loads((BUNDLED_DIR / "scenario.schema.json").read_text())
    assert kept == json.loads(json.dumps(scenario_schema(installed=False)))
    assert "flocking" not in json.dumps(kept) and "flocking" in json.dumps(scenario_schema())


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_every_bundled_scenario_is_valid_under_the_schema(path, validator):
    errors = list(validator.iter_errors(tomllib.loads(path.read_text())))
    assert not errors, jsonschema.exceptions.best_match(errors).message


@pytest.mark.parametrize(
    ("change", "where"),
    [
        (lambda d: d.update(walll=[]), "walll"),  # a misspelt table
        (lambda d: d["wall"][0].update(rect=[0, 0, 1]), "rect"),  # three numbers for four
        (lambda d: d["group"][0].update(count="two"), "count"),
        (lambda d: d.update(noise="loud"), "noise"),
        (lambda d: d.update(robot={"model": "epuck", "sensors": ["sonarr"]}), "robot.sensors"),
        (lambda d: d.update(robot={"model": "epuck", "laser": {"beems": 3}}), "beems"),
    ],
)
def test_the_schema_and_the_parser_both_refuse_a_misspelling(change, where, validator, tmp_path):
    data = tomllib.loads((BUNDLED_DIR / "zmaze.toml").read_text())
    change(data)
    assert list(validator.iter_errors(data))
    bad = tmp_path / "bad.toml"
    bad.write_text(_toml(data))
    done = subprocess.run([sys.executable, "-m", "swarm", "check", str(bad)], capture_output=True, text=True)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and str(bad) in done.stderr and where in done.stderr


def test_check_draws_the_floor_of_an_arena_and_of_a_grid(tmp_path):
    from PIL import Image

    for ref in ("zmaze", "setup1"):
        png = tmp_path / f"{ref}.png"
        done = subprocess.run([sys.executable, "-m", "swarm", "check", ref, "--png", str(png), "--json"],
                              capture_output=True, text=True)  # fmt: skip
        assert done.returncode == 0, done.stderr
        assert json.loads(done.stdout)["scenario"]["name"] == ref
        with Image.open(png) as image:
            assert image.size[0] > 300 and len(image.convert("L").getcolors(1 << 16)) > 5  # a drawing, not a blank


def _value(v) -> str:
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_value(x)}" for k, x in v.items()) + " }"
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    return json.dumps(v)


def _toml(data: dict) -> str:
    """TOML for these tests' scenarios: top-level values (inline tables too), arrays of tables."""
    lines = [f"{k} = {_value(v)}" for k, v in data.items() if not _tables(v)]
    for key, items in ((k, v) for k, v in data.items() if _tables(v)):
        for item in items:
            lines += [f"[[{key}]]", *(f"{k} = {_value(x)}" for k, x in item.items())]
    return "\n".join(lines) + "\n"


def _tables(v) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)
