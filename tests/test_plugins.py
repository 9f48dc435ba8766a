"""Parts from installed packages: a sensor declared in the entry point group `swarm.sensors` is one of
the arena's sensors, and one the arena cannot take is refused in one line saying what to do; the
command line names installed parts from their metadata and imports a package only when it is used."""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
import textwrap

import pytest

from agents.controllers import CONTROLLERS
from swarm.core.errors import ScenarioError
from swarm.scenario import scenario_schema
from tests.arena_helpers import arena
from world_server.arena.face.sensors import SENSORS

# A package of its own: a light sensor (the cosine of the heading to a lamp), a controller, and a
# note of its import in the file LOG names, so a test can tell whether a command imported it.
PACKAGE = '''
import os
from dataclasses import dataclass

import numpy as np

from world_server.arena.face.sensors import Reading, Sensor

with open(os.environ["LOG"], "a") as log:
    log.write("imported\\n")


@dataclass(frozen=True)
class Light(Sensor):
    """How much a lamp at `lamp` lights the robot's front: the cosine of its bearing, at least 0."""

    name = "light"
    rank = 50
    streams = (150,)

    lamp: tuple[float, ...] = (0.5, 0.5)
    noise: float = 0.05

    def read(self, r: Reading) -> dict[str, np.ndarray]:
        pose = r.state.pose[r.robots]
        bearing = np.arctan2(self.lamp[1] - pose[:, 1], self.lamp[0] - pose[:, 0]) - pose[:, 2]
        error = r.normal(150, 1)[:, 0] * self.noise * r.noise.factor(self.name)
        return {"light": np.maximum(np.cos(bearing) + error, 0.0)}

    def readings(self):
        return {"light": ((), "<f8")}


class Moth:
    """Turns towards the light."""

    requires = ("light",)

    def reset(self, seed, agent, params):
        self.seen = []

    def step(self, perception):
        self.seen.append(float(perception["light"]))
        return np.array([0.02, 0.03])

    def snapshot(self):
        return {"seen": list(self.seen)}

    def restore(self, state):
        self.seen = list(state["seen"])

    def record(self):
        return {"light": self.seen[-1] if self.seen else 0.0}


class NotASensor:
    name = "plain"


@dataclass(frozen=True)
class Misnamed(Light):
    name = "lux"


@dataclass(frozen=True)
class SameRank(Light):
    name = "same_rank"
    rank = 9  # range_and_bearing's


@dataclass(frozen=True)
class SameStream(Light):
    name = "same_stream"
    rank = 51
    streams = (3,)  # the IR sensor's


@dataclass(frozen=True)
class Carried(Light):
    name = "carried"
    rank = 52
    streams = (152,)
    carried = True
'''


def install(tmp_path, monkeypatch, module: str, entries: dict[str, dict[str, str]]):
    """`module` (PACKAGE) and a dist-info declaring `entries` ({group: {name: "module:attr"}}) on the path of
    this process and of those it starts, read afresh by the registries; returns the import log."""
    site = tmp_path / "site"
    dist = site / "their_parts-1.0.dist-info"
    dist.mkdir(parents=True)
    (site / f"{module}.py").write_text(PACKAGE)
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: their-parts\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text("".join(f"[{group}]\n" + "".join(f"{k} = {v}\n" for k, v in points.items())
                                                   for group, points in entries.items()))  # fmt: skip
    log = tmp_path / "imports.log"
    monkeypatch.syspath_prepend(str(site))
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [str(site), os.environ.get("PYTHONPATH")])))
    monkeypatch.setenv("LOG", str(log))
    importlib.invalidate_caches()
    for registry in (SENSORS, CONTROLLERS):
        monkeypatch.setattr(registry, "_points", None)
        monkeypatch.setattr(registry, "_made", {})
    return log


def swarm_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "swarm", *args], capture_output=True, text=True, timeout=120)


LAMP = '[[group]]\ncount = 2\ncontroller = "moth"\nstarts = [[0.3, 0.5, 0.0], [0.7, 0.5, 0.0]]\n'


def test_an_installed_sensor_is_carried_read_and_reaches_its_controller(tmp_path, monkeypatch):
    from swarm.engines.arena import ArenaEngine

    log = install(tmp_path, monkeypatch, "moths1", {"swarm.sensors": {"light": "moths1:Light"},
                                                    "swarm.controllers": {"moth": "moths1:Moth"}})  # fmt: skip
    assert "light" in SENSORS.names() and not log.exists()  # named, not imported
    robot = 'robot = { model = "epuck", sensors = ["ir", "light"], light = { lamp = [0.5, 0.5] } }\n'
    scenario = arena(LAMP + robot, noise="none", max_ticks=3)
    assert log.read_text() == "imported\n"
    assert scenario.groups[0].robot.sensors.names() == ["ir", "light"]  # in rank order: ir 2, light 50
    engine = ArenaEngine(scenario)
    engine.run()
    first = [c.seen[0] for c in engine.controllers]
    assert first == pytest.approx([1.0, 0.0])  # facing the lamp; facing away (cos -1, at least 0)
    with pytest.raises(ScenarioError, match=r"robot\.light\.lamp"):  # its table is checked as a bundled one's
        arena(LAMP + robot.replace("lamp = [0.5, 0.5]", 'lamp = "here"'))
    missing = 'robot = { model = "epuck", sensors = ["ir"] }\n'
    with pytest.raises(ScenarioError, match=r"moth needs the light sensor\(s\), which the epuck lacks"):
        arena(LAMP + missing)


def test_a_sensor_the_arena_cannot_take_is_refused_in_one_line_saying_what_to_do(tmp_path, monkeypatch, capsys):
    points = {"light": "moths2:Light", "plain": "moths2:NotASensor", "lux": "moths2:Light", "ir": "moths2:Light",
              "misnamed": "moths2:Misnamed", "same_rank": "moths2:SameRank", "same_stream": "moths2:SameStream",
              "carried": "moths2:Carried", "broken": "nowhere:Sensor"}  # fmt: skip
    install(tmp_path, monkeypatch, "moths2", {"swarm.sensors": points})
    names = [cls.name for cls in SENSORS]  # other installed packages' sensors (the example's) may be among them
    assert [n for n in names if n in points and n != "ir"] == ["light"]
    assert names.index("range_and_bearing") < names.index("light")  # in rank order: 9, then 50
    told = capsys.readouterr().err.strip().splitlines()
    expected = {
        "ir": "swarm: sensor 'ir' of moths2:Light left out: the name is taken; give the entry point another name",
        "plain": "swarm: sensor 'plain' (moths2:NotASensor) refused: moths2:NotASensor is not a Sensor class;",
        "lux": "swarm: sensor 'lux' (moths2:Light) refused: moths2:Light says name = 'light'; give the entry point",
        "misnamed": "swarm: sensor 'misnamed' (moths2:Misnamed) refused: moths2:Misnamed says name = 'lux'",
        "same_rank": "swarm: sensor 'same_rank' (moths2:SameRank) refused: moths2:SameRank has rank 9, which sensor "
        "'range_and_bearing' has; give it a rank no other sensor has",
        "same_stream": "swarm: sensor 'same_stream' (moths2:SameStream) refused: moths2:SameStream draws noise stream "
        "3, which sensor 'ir' draws; give it streams no other sensor has",
        "carried": "swarm: sensor 'carried' (moths2:Carried) refused: moths2:Carried says carried = True;",
        "broken": "swarm: sensor 'broken' (nowhere:Sensor) left out: ModuleNotFoundError: No module named 'nowhere'",
    }
    assert len(told) == len(expected), told
    for name, line in expected.items():
        assert any(t.startswith(line) for t in told), (name, told)
    assert "broken" not in SENSORS and "broken" not in SENSORS.names()
    with pytest.raises(ScenarioError, match=r"group 1\.robot\.sensors.*expected a list of .*, light, "):
        arena(LAMP.replace("moth", "wander") + 'robot = { model = "epuck", sensors = ["same_rank"] }\n')


def test_two_installed_sensors_may_not_share_a_stream(tmp_path, monkeypatch, capsys):
    install(tmp_path, monkeypatch, "moths3", {"swarm.sensors": {"light": "moths3:Light", "lux": "moths3:Misnamed"}})
    names = [c.name for c in SENSORS]
    assert "light" in names and "lux" not in names
    assert "rank 50, which sensor 'light' has" in capsys.readouterr().err  # the same rank, then the same stream


def test_the_bundled_schema_leaves_installed_sensors_out_and_the_full_one_has_them(tmp_path, monkeypatch):
    log = install(tmp_path, monkeypatch, "moths4", {"swarm.sensors": {"light": "moths4:Light"}})
    own = json.dumps(scenario_schema(installed=False))
    assert '"light"' not in own and not log.exists()  # not even imported
    full = scenario_schema()
    kind = next(k for k in full["oneOf"] if "robot" in k["properties"])  # the arena's
    robot = kind["properties"]["robot"]["oneOf"][1]["properties"]
    assert "light" in robot["sensors"]["items"]["enum"] and set(robot["light"]["properties"]) == {"lamp", "noise"}


def test_the_command_line_names_installed_parts_without_importing_them(tmp_path, monkeypatch):
    log = install(tmp_path, monkeypatch, "moths5", {"swarm.sensors": {"light": "moths5:Light"},
                                                    "swarm.controllers": {"moth": "moths5:Moth"}})  # fmt: skip
    for args in (("--help",), ("run", "--help"), ("scenarios",)):
        done = swarm_cli(*args)
        assert done.returncode == 0 and done.stderr == "", (args, done.stderr)
        assert not log.exists(), args
    assert "moth" in swarm_cli("run", "--help").stdout
    scenario = tmp_path / "moths.toml"
    scenario.write_text('kind = "arena"\nsize = [1.0, 1.0]\nmax_ticks = 5\n' + LAMP
                        + 'robot = { model = "epuck", sensors = ["light"] }\n')  # fmt: skip
    done = swarm_cli("run", str(scenario), "--json")
    assert done.returncode in (0, 1), done.stderr
    assert log.read_text() == "imported\n"  # used: imported once


def test_a_broken_installed_controller_is_left_out_only_when_it_is_asked_for(tmp_path, monkeypatch, capsys):
    install(tmp_path, monkeypatch, "moths6", {"swarm.controllers": {"moth": "moths6:Moth", "broken": "nowhere:X"}})
    assert {"moth", "broken"} <= set(CONTROLLERS.names()) and capsys.readouterr().err == ""
    assert CONTROLLERS["moth"].factory == "moths6:Moth"
    assert "broken" not in CONTROLLERS
    assert capsys.readouterr().err.strip() == ("swarm: controller 'broken' (nowhere:X) left out: ModuleNotFoundError: "
                                               "No module named 'nowhere'")  # fmt: skip
    assert "broken" not in CONTROLLERS.names()


def test_a_sensor_module_is_written_as_the_docs_show():
    """docs/sensors.md's example is the example package's sensor."""
    from pathlib import Path

    docs = (Path(__file__).parents[1] / "docs" / "sensors.md").read_text()
    assert 'neighbour_count = "swarm_flocking.sensor:NeighbourCount"' in docs
    pyproject = (Path(__file__).parents[1] / "examples" / "flocking" / "pyproject.toml").read_text()
    assert textwrap.dedent('[project.entry-points."swarm.sensors"]\nneighbour_count = ') in pyproject
