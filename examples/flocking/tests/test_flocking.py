"""The flocking package as a user's: installed beside swarm, found by its entry point, run in
process and as agent processes (lock-step equal), and recorded."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
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
