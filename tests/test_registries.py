"""Every entry of the registries does what it declares: each controller in its example scenario, each world
kind's parts on its example scenario, each experiment's smoke run, each benchmark's quick run, each arena sensor's
table and readings.  The tests are parametrized over the registries (swarm/core/registry.py), so a new
controller, world kind, experiment, benchmark or sensor is tested here as soon as its folder (its module, for a
sensor) declares it."""

from __future__ import annotations

import importlib
import inspect
import json
import tomllib
from pathlib import Path

import numpy as np
import pytest

from agents.controllers import CONTROLLERS
from agents.controllers.arena import as_action, deliver, publications
from agents.controllers.grid.dispatch import own_step, step_controller
from swarm.bench import BENCHMARKS
from swarm.core import memory_codec
from swarm.core.errors import ScenarioError
from swarm.core.kernels import EXPORTS
from swarm.core.registry import resolve
from swarm.engines.arena import ArenaEngine
from swarm.experiments import EXPERIMENTS
from swarm.scenario import BUNDLED_DIR, bundled_scenarios, load_scenario, parse_scenario_text
from tests.arena_helpers import arena
from world_server import WORLD_KINDS, kind_of, world_kind
from world_server.arena.face.sensors import SENSORS
from world_server.arena.scenario import controller_params
from world_server.grid.face import layout
from world_server.grid.face.own import GridController, run_memory, run_params

ARENA = CONTROLLERS.names(lambda c: c.world == "arena")
GRID = CONTROLLERS.names(lambda c: c.world == "grid")
WITH_TABLE = CONTROLLERS.names(lambda c: c.world == "arena" and c.table is not None)
RUN_TICKS = 30  # the engine's controller runs this long before its snapshot is taken ...
TWIN_TICKS = 8  # ... then it and its twin restored from that snapshot step side by side this long
JOBS = 2  # worker processes of an experiment's smoke run
# Benchmarks whose quick run takes over a minute on two cores, marked `experiment` (deselected by default; run them
# with -m experiment), and why.
SLOW_BENCHMARKS = {
    "distributed": "16 timed runs of world and agent processes over zenoh (10 and 50 agents, 3 pairs): 76 s",
    "executors": "four whole `swarm experiment carrot` commands, one starting Ray, one on a Ray head it starts: 55 s",
}


def _references(spec) -> list[str]:
    return [r for r in (spec.factory, spec.table, *spec.records) if r]


# ------------------------------------------------------------------ controllers


@pytest.mark.parametrize("name", CONTROLLERS.names())
def test_a_controllers_entry_names_real_sensors_kernels_parts_and_a_scenario_it_runs_in(name):
    spec = CONTROLLERS[name]
    assert spec.world in ("grid", "arena"), f"{name}: world {spec.world!r}"
    assert spec.description and "\n" not in spec.description
    if spec.world == "arena":
        unknown = set(spec.requires) - set(SENSORS.names())
        assert not unknown, f"{name} requires {sorted(unknown)}, not sensors of the arena's robots ({SENSORS.names()})"
    else:
        assert spec.requires == (), f"{name}: a grid robot carries no sensor suite"
    for module in spec.kernels:
        importlib.import_module(module)
        declared = [k for k, (kernel, _) in EXPORTS.items() if kernel.__module__ == module]
        assert declared, f"{name}: {module} declares no @exported kernel for the ahead-of-time build"
    for reference in _references(spec):
        assert resolve(reference) is not None, reference
    scenario = load_scenario(spec.example).with_overrides(controller=name)  # its robots carry what it requires
    assert kind_of(scenario).name == spec.world and scenario.controller == name


def _copy(perception: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """One controller's own copy of a perception: neither sees what the other may write into it."""
    return {k: np.array(v, copy=True) for k, v in perception.items()}


@pytest.mark.parametrize("name", ARENA)
def test_an_arena_controller_restored_from_its_encoded_snapshot_steps_on_bit_equal(name):
    spec = CONTROLLERS[name]
    scenario = load_scenario(spec.example).with_overrides(controller=name, max_ticks=RUN_TICKS + TWIN_TICKS + 10)
    engine = ArenaEngine(scenario)
    assert engine.step(RUN_TICKS) == RUN_TICKS
    saved = memory_codec.encode(engine.controllers[0].snapshot())
    twin = spec.make()
    twin.reset(scenario.seed, 0, controller_params(scenario, 0))
    twin.restore(memory_codec.decode(saved))
    assert memory_codec.encode(twin.snapshot()) == saved
    world = engine.world
    for _ in range(TWIN_TICKS):  # as the engine steps (swarm.engines.arena), with the twin beside robot 0
        perceptions = world.perceive()
        actions = np.array([as_action(c.step(_copy(p))) for c, p in zip(engine.controllers, perceptions, strict=True)])
        np.testing.assert_array_equal(as_action(twin.step(_copy(perceptions[0]))), actions[0], f"tick {world.tick}")
        shared = publications(engine.controllers, engine.agent_ids)
        assert publications([twin], [0]) == [s for s in shared if s[0] == 0], f"tick {world.tick}: what it publishes"
        deliver([*engine.controllers, twin], [*engine.agent_ids, 0], shared)
        world.apply(actions)
    assert memory_codec.encode(twin.snapshot()) == memory_codec.encode(engine.controllers[0].snapshot())


def _with_table(name: str, table: str) -> str:
    """A box with one robot of `name`, carrying the sensors it requires, and a [name] table of `table`'s lines."""
    sensors = json.dumps(list(CONTROLLERS[name].requires))
    group = f'[[group]]\ncount = 1\ncontroller = "{name}"\nrobot = {{ model = "epuck", sensors = {sensors} }}\n'
    return f"{group}[{name}]\n{table}\n"


@pytest.mark.parametrize("name", WITH_TABLE)
def test_a_bad_parameter_table_is_refused_in_one_line_that_names_the_field(name):
    with pytest.raises(ValueError) as refused:
        CONTROLLERS[name].check_table({"no_such_field": 1})
    assert "\n" not in str(refused.value) and "no_such_field" in str(refused.value)
    assert controller_params(arena(_with_table(name, "")), 0)[name] == {}  # the same file, its table empty, is fine
    with pytest.raises(ScenarioError) as refused:
        arena(_with_table(name, "no_such_field = 1"))
    message = str(refused.value)
    assert "\n" not in message and "no_such_field" in message and f"[{name}]" in message, message


@pytest.mark.parametrize("name", GRID)
def test_a_grid_controller_steps_once_on_a_fresh_perception_and_writes_a_move(name):
    spec = CONTROLLERS[name]
    kind = spec.make()
    scenario = load_scenario(spec.example).with_overrides(controller=name)
    if isinstance(kind, GridController):  # an installed package's: its own step, through the check a user's gets
        step, kind = own_step, kind.step
    else:
        assert kind == layout.controller_kind(name)  # the compiled step knows it by the same code
        step = step_controller
    pi, pf = layout.new_perception()
    act = layout.new_action()
    act[layout.A_MOVE] = -1
    step(kind, pi, pf, run_memory(scenario, 1)[0], act, run_params(scenario), np.int64(scenario.seed), 0, 1)
    assert 0 <= act[layout.A_MOVE] <= layout.STAY, act


# ------------------------------------------------------------------ experiments


def _experiment_keywords(name: str, out: Path | None) -> dict:
    """What `swarm experiment NAME` gives its run when no option is chosen (swarm/cli.py), then its smoke."""
    spec = EXPERIMENTS[name]
    kw = {o.keyword: resolve(o.collect)(o.default) if o.collect else o.default for o in spec.options}
    kw |= {"reps": None, "jobs": JOBS, "seed": 0, "out": out, **dict(spec.smoke)}
    if "progress" in inspect.signature(resolve(spec.run)).parameters:
        kw["progress"] = False
    return kw


@pytest.mark.parametrize("name", EXPERIMENTS.names())
def test_an_experiments_run_takes_every_option_and_smoke_keyword_it_declares(name):
    spec = EXPERIMENTS[name]
    assert spec.run.startswith(f"swarm.experiments.{spec.paper}."), spec.run
    inspect.signature(resolve(spec.run)).bind(name, **_experiment_keywords(name, None))
    assert all(isinstance(k, str) for k, _ in spec.smoke) and spec.writes.strip()


@pytest.mark.timeout(300)  # an experiment's smoke run: its smallest real run, up to about a minute alone
@pytest.mark.parametrize("name", EXPERIMENTS.names())
def test_an_experiments_smoke_run_writes_every_file_it_declares(name, tmp_path):
    spec = EXPERIMENTS[name]
    result = resolve(spec.run)(name, **_experiment_keywords(name, tmp_path))
    assert result["markdown"].strip() and Path(result["out"]) == tmp_path
    files = [f.strip() for f in spec.writes.split(",")]
    missing = [f for f in files if not (tmp_path / f).is_file() or (tmp_path / f).stat().st_size == 0]
    assert not missing, f"{name} wrote {sorted(p.name for p in tmp_path.iterdir())}, not {missing}"


# ------------------------------------------------------------------- benchmarks


def _benchmark(name: str):
    if name in SLOW_BENCHMARKS:
        return pytest.param(name, marks=pytest.mark.experiment, id=name)
    return name


@pytest.mark.parametrize("name", BENCHMARKS.names())
def test_a_benchmarks_options_are_keywords_its_run_takes(name):
    spec = BENCHMARKS[name]
    inspect.signature(resolve(spec.run)).bind(quick=True, **{o.keyword: o.default for o in spec.options})
    assert callable(resolve(spec.report))


@pytest.mark.parametrize("name", [_benchmark(n) for n in BENCHMARKS.names()])
def test_a_benchmarks_quick_run_reports_text(name):
    spec = BENCHMARKS[name]
    result = resolve(spec.run)(quick=True)
    json.dumps(result)  # the command line prints it with --json
    text = resolve(spec.report)(result)
    assert isinstance(text, str) and text.strip()


# ---------------------------------------------------------------------- sensors


def test_the_sensors_keep_their_order_and_each_draws_from_its_own_noise_streams():
    # The order of a robot's ray blocks and readings (a sensor added later may come anywhere among them); a stream
    # shared by two sensors would correlate their noise.
    papers = ("camera", "sonar", "ir", "laser", "odometry", "compass", "position", "contact", "zones")
    assert tuple(n for n in SENSORS.names() if n in papers) == papers
    streams = [k for cls in SENSORS for k in cls.streams]
    assert len(streams) == len(set(streams)) and 0 not in streams, streams
    assert len({cls.rank for cls in SENSORS}) == len(SENSORS.names())


def test_the_sensors_load_no_numba():
    """An agent process reads the sensors' specs (the face) without the world's kernels."""
    import subprocess
    import sys

    child = ("import sys; from world_server.arena.face.sensors import SENSORS; list(SENSORS); "
             "import world_server.arena.face.robots; "
             "print(sorted({m.split('.')[0] for m in sys.modules} & {'numba', 'scipy', 'rerun'}))")  # fmt: skip
    out = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.strip() == "[]", out.stdout + out.stderr[-2000:]


def _changed_table(cls) -> dict:
    """A table that sets every field of the sensor to something other than its default."""
    table = {}
    for f in cls.field_names():
        v = getattr(cls(), f)
        table[f] = ([round(x * 0.5, 6) for x in v] if isinstance(v, tuple) else not v if isinstance(v, bool)
                    else v + 1 if isinstance(v, int) else v * 0.5 if v else 0.02)  # fmt: skip
    if "mounts" in table:  # one per bearing, inside an e-puck
        table["mounts"] = [0.03] * len(table["bearings"])
    return table


def _sensor_robot(name: str, table: str = "", more: str = "") -> str:
    """One group of two e-pucks that carry only sensor `name` (its table: `table`)."""
    return (f'[[group]]\ncount = 2\ncontroller = "wander"\n{more}'
            f'robot = {{ model = "epuck", sensors = ["{name}"]{table} }}\n')  # fmt: skip


def _inline(table: dict) -> str:
    return "{ " + ", ".join(f"{k} = {json.dumps(v)}" for k, v in table.items()) + " }"


@pytest.mark.parametrize("name", SENSORS.names())
def test_a_sensor_parses_its_spec_from_a_scenarios_table(name):
    cls = SENSORS[name]
    table = _changed_table(cls)
    spec = cls.from_table(table)
    for f, v in table.items():
        assert getattr(spec, f) == (tuple(v) if isinstance(v, list) else v) != getattr(cls(), f), f
    extra = f", {name} = {_inline(table)}" if table else ""
    robot = arena(_sensor_robot(name, extra), noise="high").groups[0].robot
    assert robot.sensors.names() == [name] and getattr(robot.sensors, name) == spec


@pytest.mark.parametrize("name", SENSORS.names())
def test_a_bad_sensor_table_is_refused_in_one_line_that_names_the_field(name):
    cls = SENSORS[name]
    bad = {'sensors = ["radar"]': "group 1.robot.sensors", f"{name} = {{ nonsense = 1 }}": f"robot.{name}"}
    if not cls.field_names():  # a sensor without fields has no table
        bad[f"{name} = {{ nonsense = 1 }}"] = "robot"
    else:
        first = cls.field_names()[0]
        bad[f'{name} = {{ {first} = "many" }}'] = f"group 1.robot.{name}.{first}"
    for body, where in bad.items():
        text = '[[group]]\ncount = 1\ncontroller = "wander"\nrobot = { model = "epuck", ' + body + " }\n"
        with pytest.raises(ScenarioError) as err:
            arena(text)
        assert where in err.value.where and "\n" not in str(err.value), (body, str(err.value))


@pytest.mark.parametrize("name", SENSORS.names())
def test_a_sensor_reads_what_it_declares_in_a_small_arena_run(name):
    """Each reading has the declared shape and dtype, at every tick, and crosses the wire as it is."""
    from world_server.arena.face.wire import observations, parse_obs
    from world_server.arena.world import ArenaWorld

    starts = "starts = [[0.4, 0.45, 0.0], [0.4, 0.55, 0.3]]\n"  # facing a wall, near each other
    world = ArenaWorld(
        arena("[[wall]]\nrect = [0.45, 0.3, 0.5, 0.7]\n" + _sensor_robot(name, more=starts), noise="high")
    )
    declared = getattr(world.scenario.groups[0].robot.sensors, name).readings()
    for tick in range(3):
        perceptions = world.perceive()
        received = parse_obs(observations(tick, [0, 1], perceptions)).perceptions
        for p, q in zip(perceptions, received, strict=True):
            assert list(p) == list(declared), (list(p), list(declared))
            for key, (shape, dtype) in declared.items():
                value = np.asarray(p[key])
                assert value.shape == shape and value.dtype.str == dtype, (key, value.shape, value.dtype.str)
                real = value.astype(np.float64)  # only a missing neighbour's distance reads +inf
                assert np.all(np.isfinite(real) | (key == "rab_distance") & np.isposinf(real)), key
                assert np.array_equal(q[key], value), key
        world.apply(np.full((2, 2), 0.05))


# ------------------------------------------------------------------ world kinds


def _kind_references(spec) -> list[str]:
    parts = (spec.parse, spec.server, spec.runtime, spec.run, spec.warm_up, spec.review, spec.plots, spec.metrics,
             spec.print_summary, spec.overrides, spec.up_options, spec.open_recorder, spec.goals,
             spec.options, spec.check, *spec.commands)  # fmt: skip
    return [r for r in parts if r]


def test_the_world_kinds_come_default_first_and_an_unknown_one_is_named_in_one_line():
    assert WORLD_KINDS.names() == ("grid", "arena")
    assert world_kind().name == "grid" and [k.name for k in WORLD_KINDS if k.default] == ["grid"]
    with pytest.raises(ScenarioError, match=r"x.toml: kind: unknown world kind 'x'; expected one of grid, arena$"):
        parse_scenario_text('kind = "x"', "x.toml")
    assert kind_of({}) is world_kind() and kind_of({"kind": "arena"}) is WORLD_KINDS["arena"]


@pytest.mark.parametrize("name", WORLD_KINDS.names())
def test_a_world_kinds_entry_resolves_and_parses_its_bundled_scenarios(name):
    from agents.runtime import AgentRuntime

    spec = WORLD_KINDS[name]
    assert spec.description and "\n" not in spec.description
    for reference in _kind_references(spec):
        assert resolve(reference) is not None, reference
    assert isinstance(resolve(spec.server), type) and issubclass(resolve(spec.runtime), AgentRuntime)
    assert kind_of(load_scenario(spec.example)) is spec
    controllers = {c.name: c for c in CONTROLLERS if c.world == name}
    ours = [b for b in bundled_scenarios() if kind_of(load_scenario(b)) is spec]
    assert ours or name == world_kind().name, f"no bundled scenario of the {name} kind"
    for bundled in ours:  # its parser, called as the scenario loader calls it
        path = BUNDLED_DIR / f"{bundled}.toml"
        text = path.read_text()
        parsed = resolve(spec.parse)(tomllib.loads(text), text, str(path), bundled, controllers)
        assert kind_of(parsed) is spec and parsed.describe() == load_scenario(bundled).describe(), bundled


@pytest.mark.parametrize("name", WORLD_KINDS.names())
def test_a_world_kind_runs_its_example_recorded_and_reviews_the_recording(name, tmp_path, capsys):
    from swarm.cli import build_parser
    from swarm.review.report import report

    spec = WORLD_KINDS[name]
    rrd = tmp_path / "run.rrd"
    args = build_parser().parse_args(["run", spec.example, "--max-iterations", "20", "--max-ticks", "20",
                                      "--record", str(rrd), "--json"])  # fmt: skip
    common = {"agents": None, "controller": None, "seed": 1}
    scenario = resolve(spec.overrides)(load_scenario(spec.example), args, common)
    summary = resolve(spec.run)(scenario, args, None)
    done, total = spec.progress
    assert kind_of(summary) is spec and done in summary and total in summary
    assert resolve(spec.print_summary)(summary, True, args.until) in (0, 1)
    assert json.loads(capsys.readouterr().out) == summary
    result = report(rrd, tmp_path / "report")
    assert kind_of(result["summary"]) is spec and result["summary"][done] == summary[done]
    assert result["plots"] and all(Path(p).is_file() for p in result["plots"])
    assert set(result["metrics"]) <= set(resolve(spec.metrics))
