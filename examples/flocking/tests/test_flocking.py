"""The flocking package as a user's: installed beside swarm, found by its entry point, run in
process and as agent processes (lock-step equal), and recorded."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from swarm_flocking.metrics import polarization

FLOCK = str(Path(__file__).parents[1] / "flock.toml")


def swarm(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "swarm", *args], capture_output=True, text=True, timeout=300)


def summary_of(*args: str) -> dict:
    done = swarm(*args, "--json")
    assert done.returncode in (0, 1), done.stderr[-2000:]  # 1: not finished (flocking has no goal)
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_the_entry_point_names_the_controller():
    from agents.controllers import CONTROLLERS

    spec = CONTROLLERS["flocking"]
    assert spec.factory == "swarm_flocking.controller:Flocking"
    assert spec.requires == ("range_and_bearing", "compass", "ir")
    assert "flocking" in swarm("run", "--help").stdout


def test_the_robots_align_from_random_headings():
    """Vicsek's order parameter from the random start to the end of the run, on two seeds."""
    from swarm.engines.arena import ArenaEngine
    from swarm.scenario import load_scenario

    for seed in (1, 2):
        engine = ArenaEngine(load_scenario(FLOCK).with_overrides(seed=seed))
        start = {"robots": [{"pose": p} for p in engine.world.pose.tolist()]}
        end = engine.run()
        assert polarization(start) < 0.6 < 0.9 < polarization(end), (seed, polarization(start), polarization(end))


def test_a_bad_flocking_table_is_refused_in_one_line(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(Path(FLOCK).read_text().replace("separation = 0.15", "speeed = 1"))
    done = swarm("run", str(bad))
    assert done.returncode == 2 and "Traceback" not in done.stderr
    expected = (
        f"swarm: error: {bad}: [flocking]: unknown field 'speeed'; expected one of cruise, separation, "
        "speed, turn_gain, w_alignment, w_avoid, w_cohesion, w_separation"
    )
    assert done.stderr.strip().splitlines() == [expected]


def test_agent_processes_flock_exactly_as_the_in_process_run():
    args = (FLOCK, "--agents", "4", "--max-ticks", "150", "--seed", "3")
    alone, distributed = summary_of("run", *args), summary_of("up", *args, "--no-record")
    assert distributed["mode"] == "lockstep"
    assert [r["pose"] for r in distributed["robots"]] == [r["pose"] for r in alone["robots"]]


def test_a_recording_holds_what_each_robot_sensed_and_wanted(tmp_path):
    from rerun.chunk import RrdReader

    path = tmp_path / "flock.rrd"
    summary_of("run", FLOCK, "--agents", "4", "--max-ticks", "40", "--record", str(path))
    rows: dict[str, int] = {}
    for chunk in RrdReader(path).stream():
        rows[chunk.entity_path.lstrip("/")] = rows.get(chunk.entity_path.lstrip("/"), 0) + chunk.num_rows
    for agent in range(4):
        assert rows[f"controllers/{agent}/series/neighbours"] == 40
        assert rows[f"controllers/{agent}/series/wanted_turn"] == 40
    assert np.isfinite(list(rows.values())).all()


def test_the_example_sweep_runs_and_alignment_orders_the_flock(tmp_path):
    """The package's sweep file, cut to two seeds and 600 ticks: with alignment the flock is more
    polarized than without it, seed for seed."""
    import tomllib

    import swarm

    spec = tomllib.loads((Path(FLOCK).parent / "sweep.toml").read_text())
    spec.update(scenarios=[FLOCK], seeds=[1, 2], max_ticks=600, grid={"flocking.w_alignment": [0.0, 1.0]})
    rows = swarm.sweep(spec, jobs=1, out=tmp_path, progress=False)
    assert len(rows) == 4 and (tmp_path / "swarm_flocking.metrics_polarization.png").exists()
    order = {(r["flocking.w_alignment"], r["seed"]): r["swarm_flocking.metrics:polarization"] for r in rows}
    assert all(order[1.0, seed] > order[0.0, seed] for seed in (1, 2)), order


# ------------------------------------------------------------------ the package's sensor

PACKAGE = Path(__file__).parents[1]


@pytest.fixture
def sensor_installed(tmp_path, monkeypatch):
    """The package's `swarm.sensors` entry point as pip would install it (a dist-info on the path of
    this process and of the processes it starts), read afresh by the sensors' registry."""
    import importlib

    from world_server.arena.face.sensors import SENSORS

    site = tmp_path / "site"
    dist = site / "swarm_flocking_sensor-0.1.0.dist-info"
    dist.mkdir(parents=True)
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: swarm-flocking-sensor\nVersion: 0.1.0\n")
    entry = tomllib.loads((PACKAGE / "pyproject.toml").read_text())["project"]["entry-points"]["swarm.sensors"]
    (dist / "entry_points.txt").write_text("[swarm.sensors]\n" + "".join(f"{k} = {v}\n" for k, v in entry.items()))
    for folder in (PACKAGE, site):  # this checkout's package first, whatever an editable install points to
        monkeypatch.syspath_prepend(str(folder))
    monkeypatch.setenv(
        "PYTHONPATH", os.pathsep.join(filter(None, [str(PACKAGE), str(site), os.environ.get("PYTHONPATH")]))
    )
    for name in [m for m in sys.modules if m.split(".")[0] == "swarm_flocking"]:  # imported again, from here
        monkeypatch.delitem(sys.modules, name)
    importlib.invalidate_caches()
    monkeypatch.setattr(SENSORS, "_points", None)
    monkeypatch.setattr(SENSORS, "_made", {})
    return tmp_path


def crowded(tmp_path: Path, radius: float = 0.4) -> Path:
    """The package's scenario with four robots that carry neighbour_count too, without noise."""
    text = Path(FLOCK).read_text().replace("count = 12", "count = 4").replace('noise = "low"', 'noise = "none"')
    text = text.replace(
        '"range_and_bearing"] }',
        f'"range_and_bearing", "neighbour_count"], neighbour_count = {{ radius = {radius} }} }}',
    )
    path = tmp_path / "crowded.toml"
    path.write_text(text)
    return path


def test_a_scenario_carries_the_packages_sensor_and_its_reading_reaches_the_controller(sensor_installed):
    from swarm.engines.arena import ArenaEngine
    from swarm.scenario import load_scenario

    scenario = load_scenario(str(crowded(sensor_installed))).with_overrides(max_ticks=1)
    robot = scenario.groups[0].robot
    assert robot.sensors.names()[-1] == "neighbour_count" and robot.sensors.neighbour_count.radius == 0.4
    engine = ArenaEngine(scenario)
    xy = engine.world.pose[:, :2].copy()
    engine.run()
    apart = np.hypot(*(xy[None] - xy[:, None]).transpose(2, 0, 1))
    expected = ((apart <= 0.4).sum(axis=1) - 1).tolist()  # the others within the radius, at the first step
    assert [c.crowd for c in engine.controllers] == expected and all(c.counts for c in engine.controllers)
    assert engine.controllers[0].record()["crowd"] == expected[0]


def test_agent_processes_read_the_packages_sensor_as_the_in_process_run(sensor_installed):
    args = (str(crowded(sensor_installed)), "--agents", "4", "--max-ticks", "60", "--seed", "2")
    alone, distributed = summary_of("run", *args), summary_of("up", *args, "--no-record")
    assert [r["pose"] for r in distributed["robots"]] == [r["pose"] for r in alone["robots"]]
    bad = swarm("run", str(crowded(sensor_installed, radius=-1.0)))
    assert bad.returncode == 2 and "neighbour_count.radius" in bad.stderr and "Traceback" not in bad.stderr
