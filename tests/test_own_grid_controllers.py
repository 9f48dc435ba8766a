"""A user's own grid controller from outside the package (world_server.grid.face.own): its compiled
step, its memory layout and its table, named by an installed package's entry point (the example
package examples/grid_walk, installed by `make install`) or as "module:NAME"; run in process and
by agent processes (lock-step equal), resumed exactly after kill -9 of the world, and refused in
one line when its spec or its answers are bad."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import jsonschema
import numpy as np
import pytest
from numba import njit

from agents.controllers import CONTROLLERS
from swarm.core.errors import RunError, ScenarioError
from swarm.engines.grid import Engine
from swarm.scenario import load_scenario, parse_scenario_text, scenario_schema
from tests.distributed import ServerThread, free_endpoint, start_agents, stop
from world_server import persist
from world_server.grid.face.own import GridController, run_params
from world_server.grid.scenario import check_until

OUTSIDE = Path(__file__).parent / "outside"
TIMING = {"wall_seconds", "agent_steps_per_second", "ticks_per_second"}


@pytest.fixture(autouse=True)
def outside_on_path(monkeypatch):
    """The user's folder on the path of this process and of the agent processes it starts."""
    monkeypatch.syspath_prepend(str(OUTSIDE))
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [str(OUTSIDE), os.environ.get("PYTHONPATH")])))


def walk(controller: str = "walk", agents: int = 3, seed: int = 1):
    return load_scenario("setup2").with_overrides(controller=controller, agents=agents, seed=seed)


def swarm_cli(*args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "swarm", *args], capture_output=True, text=True, timeout=timeout)


def test_an_installed_packages_grid_controller_is_an_entry_and_so_is_its_module_name():
    spec = CONTROLLERS["walk"]
    assert (spec.world, spec.factory) == ("grid", "swarm_grid_walk.walk:WALK")
    assert spec.description.startswith("a correlated random walk forager")
    assert CONTROLLERS["swarm_grid_walk.walk:WALK"].world == "grid"
    own = spec.make()
    assert own.slot("detour") == 2 and own.start().tolist() == [-1, 0, 0, 0, 0, 0, 0, 0]
    assert run_params(walk()).tolist() == [0.8, 8.0]
    with pytest.raises(ScenarioError, match=r"until: walk writes no marks"):
        check_until(walk(), "converged")


@njit
def _two(pi, pf):
    pass


@njit
def _stay(pi, pf, mem, act, params, seed, agent, tick):
    pass


def test_a_bad_spec_is_refused_in_one_line():
    with pytest.raises(ValueError, match=r"is not a numba @njit function"):
        GridController(step=_two.py_func)
    with pytest.raises(ValueError, match=r"_two\(pi, pf\) takes 2 arguments; a grid step takes 8: perception"):
        GridController(step=_two)
    with pytest.raises(ValueError, match=r"memory layout of 9 words is over the memory row's 8"):
        GridController(step=_stay, memory=(("a", 5), ("b", 4)))
    with pytest.raises(ValueError, match=r"expected distinct names"):
        GridController(step=_stay, memory=(("a", 1), ("a", 1)))
    for memory in ((["a", 1],), (("a", 1, "z"),), (("a", 0),)):  # a list, a start that is not whole, no words
        with pytest.raises(ValueError, match=r"expected a tuple of \(name, words\)"):
            GridController(step=_stay, memory=memory)
    for parameters in (("speed", 1.0), (("speed", "x"),), (("speed", float("nan")),)):
        with pytest.raises(ValueError, match=r"expected a tuple of \(name, default\) pairs"):
            GridController(step=_stay, parameters=parameters)
    bad = swarm_cli("run", "setup2", "--controller", "grid_jumper:NOT_A_GRID_CONTROLLER")
    assert bad.returncode == 2 and "Traceback" not in bad.stderr, bad.stderr[-2000:]
    assert "grid_jumper:NOT_A_GRID_CONTROLLER is not a class" in bad.stderr.strip().splitlines()[-1]


def test_a_scenario_file_gives_the_controller_its_table_and_refuses_a_bad_one():
    text = ('controller = "walk"\nagents = 2\n[generator]\nwidth = 10\nheight = 10\nobstacle_density = 0.1\n'
            "resources = 2\n")  # fmt: skip
    assert run_params(parse_scenario_text(text + "[walk]\npersistence = 0.5\n", "w.toml")).tolist() == [0.5, 8.0]
    with pytest.raises(ScenarioError, match=r"w.toml: \[walk\]: unknown field\(s\) \['speed'\]; expected persistence"):
        parse_scenario_text(text + "[walk]\nspeed = 1\n", "w.toml")
    with pytest.raises(ScenarioError, match=r"w.toml: controller: cannot load controller 'nowhere:X'"):
        parse_scenario_text(text.replace('"walk"', '"nowhere:X"'), "w.toml")
    # the scenario schema (swarm schema) gives editors the same table: its fields typed, a misspelling refused
    schema = jsonschema.Draft202012Validator(scenario_schema())
    assert not list(schema.iter_errors(tomllib.loads(text + "[walk]\npersistence = 0.5\n")))
    assert list(schema.iter_errors(tomllib.loads(text + "[walk]\nspeed = 1\n")))
    assert list(schema.iter_errors(tomllib.loads(text + '[walk]\npersistence = "high"\n')))
    assert not list(schema.iter_errors(tomllib.loads(text.replace('"walk"', '"grid_jumper:JUMPER"')
                                                     + '["grid_jumper:JUMPER"]\n')))  # fmt: skip


def test_a_step_that_answers_what_the_world_refuses_or_does_not_compile_ends_the_run_in_one_line():
    cases = {
        "grid_jumper:JUMPER": r"gave robot 0 an invalid move \(expected 0\.\.4\): 9 at tick 3; the run ends",
        "grid_jumper:SCRAWLER": r"gave robot 0 an invalid mark \(below UPDATE-VALUE on its cell\): -5 at tick 0",
        "grid_jumper:TYPO": r"does not compile: Unknown attribute 'nothing'",
    }
    for name, line in cases.items():
        with pytest.raises(RunError, match=rf"^grid controller '{name}' {line}"):
            Engine(walk(name, agents=2)).run()
    ran = swarm_cli("run", "setup2", "--controller", "grid_jumper:JUMPER", "--agents", "2")
    assert ran.returncode == 2 and "Traceback" not in ran.stderr, ran.stderr[-2000:]
    assert ran.stderr.strip().splitlines()[-1].startswith("swarm: error: grid controller 'grid_jumper:JUMPER' gave")
    # No cached index may hold a step's numba Dispatcher type: its pickled weak reference dies in the next
    # process that loads the index, and that process's next save of it raises ReferenceError.
    holding = [p.name for p in Path(os.environ["NUMBA_CACHE_DIR"]).rglob("*.nbi") if b"Dispatcher" in p.read_bytes()]
    assert holding == []


def test_an_agent_process_ends_in_the_same_one_line():
    endpoint = free_endpoint()
    world = ServerThread(walk("grid_jumper:JUMPER", agents=1), "own-grid-bad", endpoint, deadline=5.0).start()
    (agent,) = start_agents(endpoint, "own-grid-bad", "grid_jumper:JUMPER", 1)
    try:
        assert agent.wait(timeout=240) == 2
        err = agent.stderr.read().decode().strip().splitlines()
        assert "Traceback" not in "\n".join(err)
        assert err[-1].startswith("swarm: error: grid controller 'grid_jumper:JUMPER' gave robot 0 an invalid move")
    finally:
        stop([agent])
        world.close()


def test_swarm_up_equals_swarm_run_bit_for_bit():
    args = ["setup2", "--agents", "3", "--seed", "1", "--controller", "walk", "--json"]
    up = swarm_cli("up", *args, "--run-id", "owngridup", "--listen", free_endpoint(), "--no-record")
    assert up.returncode == 0, up.stderr[-3000:]
    a, b = json.loads(up.stdout), Engine(walk()).run().summary  # `swarm run`'s summary, in this process
    assert b["finished"] and b["delivered"] == b["total"] and b["controller"] == "walk"
    same = set(b) - TIMING
    assert {k: a[k] for k in same} == {k: b[k] for k in same}
    assert a["rejected_messages"] == 0 and a["agents_lost"] == 0


def test_kill_9_the_world_then_a_restart_ends_exactly_as_swarm_run(tmp_path):
    """The saved state holds the world and the user's controllers' memory rows: after kill -9 of
    the world at tick 200 or later, a restarted world ends with the in-process run's result."""
    engine = Engine(walk())
    expected = engine.run().summary
    endpoint, state, summary_file = free_endpoint(), persist.state_path(tmp_path, "owngrid"), tmp_path / "summary.json"
    world_cmd = [sys.executable, "-m", "swarm", "world", "setup2", "--agents", "3", "--seed", "1", "--controller",
                 "walk", "--run-id", "owngrid", "--listen", endpoint, "--state-dir", str(tmp_path), "--persist-every",
                 "20", "--deadline", "10", "--summary-file", str(summary_file)]  # fmt: skip
    world = subprocess.Popen(world_cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    procs = [world, *start_agents(endpoint, "owngrid", "walk", 1, count=3)]
    try:
        deadline = time.monotonic() + 240
        while (saved := persist.load(state) if state.exists() else None) is None or saved["tick"] < 200:
            assert time.monotonic() < deadline and world.poll() is None, "the world never persisted"
            time.sleep(0.01)
        os.kill(world.pid, signal.SIGKILL)
        world.wait()
        before = persist.load(state)
        assert before["tick"] >= 200 and before["memory"].shape == (3, 8)  # the walkers' memory rows were saved
        world = subprocess.Popen(world_cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        procs.append(world)
        assert world.wait(timeout=300) == 0, world.stderr.read().decode()[-3000:]
        summary = json.loads(summary_file.read_text())
        for key in ("iterations", "delivered", "total", "finished"):
            assert summary[key] == expected[key], (key, before["tick"])
        assert summary["missed_ticks"] == 0 and summary["rejected_messages"] == 0
        final = persist.load(state)
        np.testing.assert_array_equal(final["pos"], engine.world.pos)
        np.testing.assert_array_equal(final["memory"], engine.mem)
    finally:
        stop(procs)
