"""fingerprint-robustness (swarm/experiments/tapus2006/robustness.py): real short runs on the office floor."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from swarm.experiments.tapus2006.fingerprint import tour_scenario
from swarm.experiments.tapus2006.robustness import (
    BASELINE,
    kidnap_waypoints,
    recovery,
    robustness_job,
    run_robustness_experiment,
    short_routes,
)

WAYPOINTS = 8  # the mapping tour's first stretch, driven twice: seconds, not minutes


@pytest.fixture(scope="module")
def routes():
    return short_routes(tour_scenario("office", "mapping", "low", 0), WAYPOINTS, "new-path")


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    out = tmp_path_factory.mktemp("robustness")
    result = run_robustness_experiment("fingerprint-robustness", None, 1, 1, 0, out, progress=False,
                                       conditions=("kidnap",), waypoints=WAYPOINTS)  # fmt: skip
    return out, result


def test_the_experiment_writes_its_files(written):
    out, result = written
    for name in ("runs.csv", "summary.csv", "table.md", "plot.png"):
        assert (out / name).is_file() and (out / name).stat().st_size > 0, name
    assert "kidnapping" in result["markdown"] and "development seeds 0..0" in result["markdown"]


def test_a_kidnapping_yields_a_recovery_count_or_a_censored_flag(written):
    out, _ = written
    with open(out / "runs.csv") as f:
        rows = list(csv.DictReader(f))
    kid = [r for r in rows if r["condition"] == "kidnap"]
    assert len(kid) == 1 and {r["condition"] for r in rows} == {BASELINE, "kidnap"}
    r = kid[0]
    at, total = int(r["kidnapped_at"]), int(r["fingerprints"])
    assert 0 < at < total and float(r["moved_m"]) > 0
    for f in ("grid", "links"):
        count, recovered = int(r[f"recovery_{f}"]), r[f"recovered_{f}"] == "True"
        assert 1 <= count <= total - at
        assert recovered or count == total - at  # not recovered: censored at the tour's end
    with open(out / "summary.csv") as f:
        summary = [s for s in csv.DictReader(f) if s["condition"] == "kidnap"]
    assert summary and int(summary[0]["n"]) == 1 and summary[0]["censored_grid"] in ("0", "1")


def test_zero_camera_noise_equals_the_baseline_run_exactly(routes):
    base = robustness_job(("office", BASELINE, math.nan, 3, routes, "new-path"))
    quiet = robustness_job(("office", "camera", 0.0, 3, routes, "new-path"))
    skip = {"condition", "level", "wall_seconds"}
    assert {k: v for k, v in base.items() if k not in skip} == {k: v for k, v in quiet.items() if k not in skip}


def test_the_conditions_reach_the_sensors_through_their_tables():
    s = tour_scenario("office", "mapping", "low", 0, sensors={"camera": {"noise": 20.0, "range_noise": 0.1},
                                                               "compass": {"bias": 0.1}})  # fmt: skip
    cam = s.groups[0].robot.sensors.camera
    assert (cam.noise, cam.range_noise, s.groups[0].robot.sensors.compass.bias) == (20.0, 0.1, 0.1)
    plain = tour_scenario("office", "mapping", "low", 0).groups[0].robot.sensors.camera
    assert (plain.noise, plain.range_noise) == (0.0, 0.0)
    with pytest.raises(ValueError, match="nonsense"):
        tour_scenario("office", "mapping", "low", 0, sensors={"camera": {"nonsense": 1}})


def test_recovery_counts_from_the_kidnapping_skips_off_map_prints_and_censors_at_the_end():
    right = np.array([1, 1, 1, 0, 0, -1, 1, 1, -1, 1, 0], np.int8)  # kidnapped at 3
    assert recovery(right, 3, hold=3) == (4, True)  # the 4th print after the kidnapping starts 3 right in a row
    assert recovery(right, 3, hold=4) == (8, False)  # never 4 in a row on the map: censored at the tour's end
    assert recovery(np.array([1, 1], np.int8), 2) == (0, False)


def test_the_kidnapper_carries_the_robot_forward_to_the_farthest_later_waypoint():
    route = [(float(x), 0.0) for x in range(20)]
    for seed in range(5):
        a, b = kidnap_waypoints(route, seed)
        assert 5 <= a < 10 and b == 14
