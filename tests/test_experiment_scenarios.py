"""Every experiment takes `--scenario FILE`: it runs its conditions on that floor, and a floor that lacks what
the experiment needs is refused in one line (exit status 2 on the command line) before any run starts."""

from __future__ import annotations

import inspect
import subprocess
import sys
from pathlib import Path

import pytest

from swarm.core.errors import ScenarioError
from swarm.core.registry import resolve
from swarm.experiments import EXPERIMENTS
from swarm.experiments.girard2005 import bg
from swarm.experiments.simonin2007.floors import paper_floor

ROOT = Path(__file__).resolve().parents[1]
GRID = ("table1", "table2", "ants", "congestion", "tuning")  # simonin2007's experiments that run on a user's floor
TINY = '''quantity = 100
[map]
ascii = """
#########
#R.....R#
#...B...#
#R.....R#
#########
"""
'''
NO_RESOURCE = '[map]\nascii = """\n#####\n#.B.#\n#####\n"""\n'
NO_BASE = '[map]\nascii = """\n#####\n#.R.#\n#####\n"""\n'
NO_RESOURCE_DRAWN = "[generator]\nwidth = 10\nheight = 10\nobstacle_density = 0.1\nresources = 0\n"
HALL = """kind = "arena"
name = "hall"
size = [6, 3]
robot = "scout"
noise = "low"
control_period = 0.1
max_ticks = 3000

[routes]
mapping = [[0.6, 1.5], [2.0, 1.5], [4.0, 1.5], [5.4, 1.5]]

[[group]]
count = 1
controller = "carrot"
start = [0.6, 1.5, 0.0]
route = "mapping"

[[wall]]
name = "south"
rect = [0, 0, 6, 0.1]
colour = 200

[[wall]]
name = "north"
rect = [0, 2.9, 6, 3]
colour = 200

[[wall]]
name = "west"
rect = [0, 0, 0.1, 3]
colour = 60

[[wall]]
name = "east"
rect = [5.9, 0, 6, 3]
colour = 120
"""
PLACES = """
[[zone]]
kind = "place"
name = "west_half"
rect = [0.1, 0.1, 3.0, 2.9]

[[zone]]
kind = "place"
name = "east_half"
rect = [3.0, 0.1, 5.9, 2.9]
"""


def _floor(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return str(path)


def _run(name: str, out: Path, scenario: str, **changes) -> dict:
    """The experiment's smoke run (ExperimentSpec.smoke) in this process, on `scenario`."""
    spec = EXPERIMENTS[name]
    kw = {o.keyword: resolve(o.collect)(o.default) if o.collect else o.default for o in spec.options}
    kw |= {"reps": None, "jobs": 1, "seed": 0, "out": out, **dict(spec.smoke), "scenario": scenario, **changes}
    if "progress" in inspect.signature(resolve(spec.run)).parameters:
        kw["progress"] = False
    return resolve(spec.run)(name, **kw)


def _wrote_every_file(name: str, out: Path) -> None:
    files = [f.strip() for f in EXPERIMENTS[name].writes.split(",")]
    missing = [f for f in files if not (out / f).is_file() or (out / f).stat().st_size == 0]
    assert not missing, f"{name} wrote {sorted(p.name for p in out.iterdir())}, not {missing}"


@pytest.mark.parametrize("name", EXPERIMENTS.names())
def test_every_experiment_declares_a_scenario_option_its_run_takes(name):
    spec = EXPERIMENTS[name]
    assert "--scenario" in [o.flag for o in spec.options], f"{name} takes no --scenario"
    assert "scenario" in inspect.signature(resolve(spec.run)).parameters


@pytest.mark.timeout(180)  # the first run compiles the grid kernels: minutes on a loaded machine
@pytest.mark.parametrize("name", GRID)
def test_a_grid_experiment_runs_its_conditions_on_the_users_floor_without_the_papers_numbers(name, tmp_path):
    floor = _floor(tmp_path, "tiny", TINY)
    extra = {"tuning_sizes": None} if name == "tuning" else {}
    result = _run(name, tmp_path / "out", floor, **extra)
    _wrote_every_file(name, tmp_path / "out")
    md = result["markdown"]
    assert "the user's floor tiny (9x5)" in md and "paper:" not in md and "Paper (" not in md
    if name != "tuning":  # the tables' runs.csv names each run's floor
        runs = (tmp_path / "out" / "runs.csv").read_text().splitlines()[1:]
        assert {line.split(",")[1] for line in runs} == {floor}


def test_the_papers_numbers_belong_to_the_experiments_own_floors():
    assert paper_floor("table1", "setup1") and paper_floor("congestion", "setup1") and paper_floor("ants", "setup3-50")
    assert not paper_floor("table1", "setup2") and not paper_floor("table2", "maze") and not paper_floor("table3", "")


@pytest.mark.parametrize("name", GRID)
@pytest.mark.parametrize(("floor", "said"), [
    (NO_RESOURCE, "map.ascii: " + "{name} needs resources to forage: the map has no R"),
    (NO_RESOURCE_DRAWN, "generator.resources: {name} needs resources"),
    (NO_BASE, "expected exactly one base B, found 0"),
    (None, "kind: {name} forages on a grid floor"),
])  # fmt: skip
def test_a_grid_experiment_refuses_a_floor_without_a_base_or_resources_or_an_arena_one(name, floor, said, tmp_path):
    scenario = "office" if floor is None else _floor(tmp_path, "floor", floor)
    extra = {"tuning_sizes": None} if name == "tuning" else {}
    with pytest.raises(ScenarioError, match=said.format(name=name)):
        _run(name, tmp_path / "out", scenario, **extra)
    assert not (tmp_path / "out").exists()


def test_table3_and_tunings_sizes_refuse_one_floor_in_one_line(tmp_path):
    floor = _floor(tmp_path, "tiny", TINY)
    with pytest.raises(ScenarioError, match=r"table3 varies the floor's size.*use table1's design or a sweep"):
        _run("table3", tmp_path / "out", floor)
    with pytest.raises(ScenarioError, match="--tuning-sizes: --scenario gives the one floor to tune on"):
        _run("tuning", tmp_path / "out", floor)  # its smoke chooses sizes


@pytest.mark.timeout(60)
def test_bg_colony_lives_on_the_users_floor_and_refuses_a_grid_one(tmp_path):
    result = _run("bg-colony", tmp_path / "out", "tmaze-1", max_ticks=100)
    _wrote_every_file("bg-colony", tmp_path / "out")
    assert "the user's floor tmaze-1" in result["markdown"] and "14431.5" not in result["markdown"]
    with pytest.raises(ScenarioError, match="bg-colony runs on an arena floor"):
        _run("bg-colony", tmp_path / "grid", _floor(tmp_path, "tiny", TINY))


@pytest.mark.timeout(90)
def test_bg_ablations_run_both_experiments_on_the_users_t_maze(tmp_path, monkeypatch):
    monkeypatch.setattr(bg, "TEST_SECONDS", 20.0)  # short tests (one process: the change reaches every run)
    result = _run("bg-ablations", tmp_path / "out", "tmaze-1.5", ratios=None, mapping_seconds=30.0)
    _wrote_every_file("bg-ablations", tmp_path / "out")
    assert "the user's floor tmaze-1.5" in result["markdown"] and "ratio 1.5" in result["markdown"]
    with pytest.raises(ScenarioError, match="bg-ablations needs Ep1, Ep2, below_left, below_right"):
        _run("bg-ablations", tmp_path / "exp1", "bg-exp1", ratios=None)
    with pytest.raises(ScenarioError, match="--ratios chooses the tmaze-R floors"):
        _run("bg-ablations", tmp_path / "both", "tmaze-1")


@pytest.mark.timeout(60)
def test_fingerprint_together_shares_the_floors_mapping_route_among_the_team(tmp_path):
    result = _run("fingerprint-together", tmp_path / "out", _floor(tmp_path, "hall", HALL + PLACES))
    _wrote_every_file("fingerprint-together", tmp_path / "out")
    assert "`" + str(tmp_path / "hall.toml") + "`" in result["markdown"]
    with pytest.raises(ScenarioError, match="zones: fingerprint-together needs place zones"):
        _run("fingerprint-together", tmp_path / "bare", _floor(tmp_path, "bare", HALL))
    with pytest.raises(ScenarioError, match="routes: fingerprint-together needs a 'mapping' route"):
        _run("fingerprint-together", tmp_path / "none", _floor(tmp_path, "none", HALL.replace("mapping =", "x =")
                                                                .replace('"mapping"', '"x"') + PLACES))  # fmt: skip


@pytest.mark.parametrize(("name", "floor", "said"), [
    ("table1", NO_RESOURCE, "the map has no R"),
    ("table3", TINY, "table3 varies the floor's size"),
    ("bg-colony", TINY, "bg-colony runs on an arena floor"),
    ("bg-ablations", None, "bg-ablations needs Ep1, Ep2"),
    ("fingerprint-together", HALL, "needs place zones"),
    ("fingerprint-map", TINY, "the fingerprint experiments map an arena floor"),
])  # fmt: skip
def test_the_command_refuses_a_floor_lacking_what_the_experiment_needs_in_one_line(name, floor, said, tmp_path):
    scenario = "bg-exp1" if floor is None else _floor(tmp_path, "floor", floor)
    done = subprocess.run([sys.executable, "-m", "swarm", "experiment", name, "--scenario", scenario, "--reps", "2",
                           "--out", str(tmp_path / "out")], capture_output=True, text=True, cwd=ROOT,
                          timeout=60)  # fmt: skip
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1 and said in lines[0], done.stderr
    assert lines[0].startswith("swarm: error: ") and not (tmp_path / "out").exists()
