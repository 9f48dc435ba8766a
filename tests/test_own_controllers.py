"""A user's own arena controller, from outside the package: named "module:Class" on the command
line or in a scenario, or declared by an installed package's entry point; run in process and in
agent processes (lock-step equal), recorded without a module of its own, and kept from ending
everyone's run when it raises."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from agents.controllers import CONTROLLERS
from swarm.core.errors import RunError, ScenarioError
from swarm.core.registry import ControllerSpec, Registry, UnknownPart
from swarm.engines.arena import ArenaEngine
from swarm.scenario import load_scenario
from tests.arena_helpers import arena, resumed_pair, rrd_rows
from tests.distributed import run_world

OUTSIDE = Path(__file__).parent / "outside"


@pytest.fixture(autouse=True)
def outside_on_path(monkeypatch):
    """The user's folder on the path of this process and of the agent processes it starts."""
    monkeypatch.syspath_prepend(str(OUTSIDE))
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [str(OUTSIDE), os.environ.get("PYTHONPATH")])))


def zmaze(controller: str, agents: int = 3, ticks: int = 40):
    return load_scenario("zmaze").with_overrides(controller=controller, agents=agents, max_ticks=ticks)


def swarm_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "swarm", *args], capture_output=True, text=True, timeout=120)


def test_a_class_named_module_colon_class_is_an_entry_described_by_itself():
    spec = CONTROLLERS["circlers:Circler"]
    assert (spec.world, spec.factory, spec.requires) == ("arena", "circlers:Circler", ("ir",))
    assert spec.description == "Drives in a circle; its [table] sets the turn."
    assert "circlers:Circler" in CONTROLLERS and "circlers:Nothing" not in CONTROLLERS
    with pytest.raises(UnknownPart, match=r"cannot load controller 'nowhere:X': ModuleNotFoundError.*PYTHONPATH"):
        CONTROLLERS["nowhere:X"]
    with pytest.raises(UnknownPart, match=r"lacks step\(\), snapshot\(\), restore\(\), record\(\)"):
        CONTROLLERS["circlers:NotAController"]


def test_a_copied_out_controller_runs_bit_for_bit_as_the_registered_one(tmp_path, monkeypatch):
    """wander's own module, copied out of the package, is the same controller by another name."""
    source = Path(importlib.util.find_spec(CONTROLLERS["wander"].factory.partition(":")[0]).origin)
    (tmp_path / "my_wander.py").write_text(source.read_text())
    monkeypatch.syspath_prepend(str(tmp_path))
    ours, theirs = ArenaEngine(zmaze("wander", ticks=300)), ArenaEngine(zmaze("my_wander:WanderController", ticks=300))
    ours.run(), theirs.run()
    np.testing.assert_array_equal(ours.world.pose, theirs.world.pose)
    assert ours.world.bodies.distance.sum() > 0.5  # the robots went somewhere


def test_a_scenario_names_a_users_controller_and_its_table_is_checked_and_given():
    group = '[[group]]\ncount = 2\ncontroller = "circlers:Circler"\nstarts = [[0.3, 0.5], [0.7, 0.5]]\n'
    s = arena(group + '["circlers:Circler"]\nturn = 0.25\n', max_ticks=20)
    engine = ArenaEngine(s)
    assert engine.controllers[0].turn == 0.25  # params["table"]: its own table, whatever its name
    engine.run()
    with pytest.raises(ScenarioError, match=r"\[circlers:Circler\].*unknown field 'speed'; expected turn"):
        arena(group + '["circlers:Circler"]\nspeed = 1\n')
    with pytest.raises(ScenarioError, match=r"group 1.controller.*cannot load controller 'nowhere:X'"):
        arena(group.replace("circlers:Circler", "nowhere:X"))


def test_the_command_line_takes_module_colon_class_and_refuses_a_bad_one_in_one_line():
    ran = swarm_cli("run", "zmaze", "--controller", "circlers:Circler", "--max-ticks", "20", "--json")
    assert ran.returncode in (0, 1), ran.stderr
    assert '"controller": "circlers:Circler"' in ran.stdout
    bad = swarm_cli("run", "zmaze", "--controller", "circlers:NotAController")
    assert bad.returncode == 2 and "Traceback" not in bad.stderr
    assert bad.stderr.strip().splitlines()[-1].startswith("swarm run: error: argument --controller: cannot load")


def test_agent_processes_run_a_users_controller_lock_step_equal_to_in_process():
    scenario = zmaze("circlers:Circler", agents=3, ticks=60)
    expected = ArenaEngine(scenario)
    expected.run()
    _, world = run_world(scenario, "own-lockstep", [("circlers:Circler", 1, 3)], deadline=60.0)
    np.testing.assert_array_equal(world.pose, expected.world.pose)


def test_a_users_controller_resumes_exactly_from_its_snapshot():
    a, b = resumed_pair(zmaze("circlers:Circler", agents=3, ticks=80), 40)
    np.testing.assert_array_equal(a.world.pose, b.world.pose)
    assert [c.ticks for c in a.controllers] == [c.ticks for c in b.controllers] == [80] * 3


def test_a_controller_that_raises_stops_its_robot_and_the_run_goes_on_alike_in_both_runtimes(capsys):
    scenario = zmaze("circlers:FailsAtTick", agents=3, ticks=60)
    engine = ArenaEngine(scenario)
    out = engine.run()
    told = capsys.readouterr().err.strip().splitlines()
    assert told == ["swarm: controller 'circlers:FailsAtTick' of robot 1 raised ZeroDivisionError: a user's bug at "
                    "tick 4; the robot holds still for the rest of the run (--on-controller-error stop ends the run "
                    "instead)"]  # fmt: skip
    assert out["controller_failures"] == {"1": "ZeroDivisionError: a user's bug"}
    assert sum(out["rejected"].values()) == 0  # the robot holds still with a valid answer
    moved = [r["distance"] for r in out["robots"]]
    assert moved[0] > 2 * moved[1] and moved[2] > 2 * moved[1]  # the others drove on
    summary, world = run_world(scenario, "own-fails", [("circlers:FailsAtTick", 1, 3)], deadline=60.0)
    np.testing.assert_array_equal(world.pose, engine.world.pose)
    assert summary["rejected_by_reason"] == {} and summary["wall_seconds"] < 30  # no deadline waited out
    with pytest.raises(RunError, match=r"robot 1 raised ZeroDivisionError: a user's bug at tick 4; the run stops"):
        ArenaEngine(scenario, on_error="stop").run()


def test_a_reset_that_raises_an_answer_of_text_and_a_failing_record_are_one_line_each(tmp_path, capsys):
    from swarm.recording.arena import ArenaRecorder

    with pytest.raises(RunError, match=r"'circlers:FailsInReset' of robot 0 cannot start: KeyError: 'no such thing'"):
        ArenaEngine(zmaze("circlers:FailsInReset", agents=2, ticks=20))
    out = ArenaEngine(zmaze("circlers:AnswersText", agents=1, ticks=20)).run()
    assert out["rejected"]["not finite"] == 20 and "answered shape ()" in capsys.readouterr().err
    engine = ArenaEngine(zmaze("circlers:RecordsNowAndThen", agents=2, ticks=20))
    path = tmp_path / "sometimes.rrd"
    recorder = ArenaRecorder(path, engine.world, engine.goals, {"run_id": "s"}, controllers=engine.controllers)
    recorder.close(engine.run(recorder=recorder))
    assert "leaves out robot 1's record()" in capsys.readouterr().err
    rows = rrd_rows(path)
    assert rows["controllers/0/series/even"] == rows["controllers/0/series/late"] == 20  # NaN where missing
    assert not any(k.startswith("controllers/1/") for k in rows)


def test_a_nan_answer_is_told_once_and_counted_every_tick(capsys):
    out = ArenaEngine(zmaze("circlers:AnswersNaN", agents=2, ticks=30)).run()
    told = capsys.readouterr().err.strip().splitlines()
    assert len(told) == 1 and "robot 0 answered NaN or infinite wheel speeds at tick 0" in told[0]
    assert out["rejected"]["not finite"] == 30 and "controller_failures" not in out
    engine = ArenaEngine(zmaze("circlers:AnswersNaN", agents=2, ticks=30))
    engine.run()
    summary, world = run_world(engine.scenario, "own-nan", [("circlers:AnswersNaN", 1, 2)], deadline=60.0)
    np.testing.assert_array_equal(world.pose, engine.world.pose)  # the refused robot held still in both
    assert summary["rejected_by_reason"] == {"act: not finite": 30} and summary["agents_lost"] == 0
    assert summary["wall_seconds"] < 30  # a refused answer is an answer: no deadline waited out


def test_a_recording_shows_any_record_by_its_shape(tmp_path):
    from swarm.recording.arena import RECORD_LOG, ArenaRecorder, records_of

    engine = ArenaEngine(zmaze("circlers:Circler", agents=2, ticks=30))
    assert records_of(engine.scenario) == [(RECORD_LOG,)] * 2
    assert records_of(load_scenario("zmaze").with_overrides(controller="dft"))[0] == CONTROLLERS["dft"].records
    path = tmp_path / "own.rrd"
    recorder = ArenaRecorder(path, engine.world, engine.goals, {"run_id": "own"}, controllers=engine.controllers)
    recorder.close(engine.run(recorder=recorder))
    rows = rrd_rows(path)
    for a in (0, 1):
        assert rows[f"controllers/{a}/series/ticks"] == 30  # a number: a series, every tick
        assert rows[f"controllers/{a}/bars/wheels"] == rows[f"controllers/{a}/images/grid"] == 3  # ticks 0, 10, 20
        assert rows[f"world/records/{a}/trail"] == 3  # N x 2: a path over the arena
    assert not any("note" in k for k in rows)  # text is left out


def test_an_installed_packages_entry_point_is_a_controller_and_a_broken_one_is_left_out(tmp_path, monkeypatch, capsys):
    dist = tmp_path / "their_package-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: their-package\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text("[swarm.controllers]\ncircler = circlers:Circler\nbroken = nowhere:X\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    registry = Registry("controller", "agents.controllers", "CONTROLLERS", plugins="swarm.controllers",
                        external=ControllerSpec.of_plugin)  # fmt: skip
    assert registry["circler"].factory == "circlers:Circler" and "wander" in registry
    assert "broken" not in registry
    assert "controller 'broken' (nowhere:X) left out: ModuleNotFoundError" in capsys.readouterr().err


def test_the_viewer_opens_on_the_arena_and_what_explains_each_groups_controller():
    import rerun.blueprint as rrb

    from swarm.recording.arena import blueprint, records_of

    own = {"/controllers/0/series", "/controllers/0/bars", "/controllers/0/images"}
    cases = (("dft", 1, {"/fields/0/M", "/fields/0/I", "/fields/0/intention", "/fields/0/action"}),
             ("circlers:Circler", 2, own))  # fmt: skip
    for controller, agents, origins in cases:
        scenario = zmaze(controller, agents=agents)
        arena_view, _, explained = blueprint(rrb, scenario, records_of(scenario)).root_container.contents
        assert arena_view.origin == "/world"
        assert {str(v.origin) for v in explained.contents} == origins  # the group's first robot


def test_an_installed_packages_flocking_agents_equal_the_in_process_run_bit_for_bit():
    """The example package's controller (entry point `flocking`) with its range-and-bearing broadcasts,
    as agent processes in lock-step: every pose equal to the in-process run's, not only to the summary's
    decimals."""
    flock = Path(__file__).resolve().parents[1] / "examples" / "flocking" / "flock.toml"
    if "flocking" not in CONTROLLERS:
        pytest.skip("the example package is not installed (make install installs it)")
    scenario = load_scenario(str(flock)).with_overrides(agents=4, max_ticks=150, seed=3)
    engine = ArenaEngine(scenario)
    engine.run()
    summary, world = run_world(scenario, "own-flock", [("flocking", 2, 2)], deadline=60.0)
    assert summary["agents_lost"] == 0
    np.testing.assert_array_equal(world.pose, engine.world.pose)
