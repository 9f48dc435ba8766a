"""`swarm sweep`: a grid of scenario parameters × seeds, resumable, each run the one a scenario file gives."""

from __future__ import annotations

import argparse
import csv
import math
import pickle
from dataclasses import replace

import pandas as pd
import pytest

from swarm.cli import main
from swarm.cli_arena import run_arena
from swarm.cli_grid import run_grid
from swarm.core.errors import ScenarioError
from swarm.scenario import load_scenario, parse_scenario_data, parse_scenario_text, scenario_path, scenario_tables
from swarm.sweeps import run_sweep
from swarm.sweeps.jobs import assign

METRICS = ["reached", "collisions", "mean_path_ratio", "distance"]
TINY = {"scenarios": ["zmaze"], "controller": "wander", "seeds": [1, 2], "max_ticks": 50, "metrics": METRICS,
        "grid": {"wander.speed": [0.4, 0.8]}}  # fmt: skip


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep")
    return out, run_sweep(TINY, jobs=2, out=out, progress=False)


def _comparable(rows: list[dict], drop: str = "") -> list[dict]:
    """Rows with nan as text (nan equals nothing) and without the column `drop`."""
    return [
        {k: "nan" if isinstance(v, float) and math.isnan(v) else v for k, v in r.items() if k != drop} for r in rows
    ]


def _rows(path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_a_tiny_sweep_writes_its_runs_summary_and_plots(tiny):
    out, result = tiny
    runs = _rows(out / "runs.csv")
    assert list(runs[0]) == ["scenario", "wander.speed", "agents", "seed", *METRICS, "wall_s"]
    assert [(r["wander.speed"], r["seed"]) for r in runs] == [("0.4", "1"), ("0.4", "2"), ("0.8", "1"), ("0.8", "2")]
    assert result["ran"] == 4 and len(result["rows"]) == 4
    summary = _rows(out / "summary.csv")
    assert [(r["wander.speed"], r["n"]) for r in summary] == [("0.4", "2"), ("0.8", "2")]
    assert {"distance_mean", "distance_std", "distance_ci_low", "distance_ci_high"} <= set(summary[0])
    assert all((out / f"{m}.png").stat().st_size > 1000 for m in METRICS)
    assert result["no_parquet"] is None and len(pd.read_parquet(out / "runs.parquet")) == 4
    # wander drives at a share of the wheel limit: twice the speed, about twice the distance
    assert float(summary[1]["distance_mean"]) > 1.5 * float(summary[0]["distance_mean"])


def test_a_rerun_runs_nothing_again_and_a_deleted_row_is_run_again(tiny):
    out, first = tiny
    again = run_sweep(TINY, jobs=1, out=out, progress=False)
    assert again["ran"] == 0 and _comparable(again["rows"]) == _comparable(first["rows"])
    lines = (out / "runs.csv").read_text().splitlines(keepends=True)
    (out / "runs.csv").write_text("".join(lines[:2] + lines[3:]) + "zmaze,0.8,1,")  # a row gone, one cut short
    resumed = run_sweep(TINY, jobs=1, out=out, progress=False)
    assert resumed["ran"] == 1
    assert _comparable(resumed["rows"], "wall_s") == _comparable(first["rows"], "wall_s")
    assert len(_rows(out / "runs.csv")) == 4
    with pytest.raises(ValueError, match="were made with"):  # other fixed settings: not these runs
        run_sweep(TINY | {"max_ticks": 60}, jobs=1, out=out, progress=False)


def test_a_sweep_run_equals_the_run_of_a_scenario_file_with_the_same_table(tiny):
    _, result = tiny
    text = scenario_path("zmaze").read_text() + "\n[wander]\nspeed = 0.8\n"
    scenario = parse_scenario_text(text, "zmaze.toml").with_overrides(controller="wander", seed=2, max_ticks=50)
    summary = run_arena(scenario, argparse.Namespace(json=True, record=None))
    row = next(r for r in result["rows"] if r["wander.speed"] == 0.8 and r["seed"] == 2)
    assert row["distance"] == sum(r["distance"] for r in summary["robots"]) / len(summary["robots"])
    assert row["collisions"] == summary["collisions"] and row["reached"] == summary["reached"]
    assert math.isnan(row["mean_path_ratio"]) and summary["mean_path_ratio"] is None


@pytest.mark.parametrize(
    "body, says",
    [
        ('controller = "wander"\n[grid]\n"wander.sped" = [0.4]', "unknown field 'sped'"),
        ('controller = "wander"\n[grid]\n"wander.speed" = ["fast"]', "expected a number"),
        ('[grid]\n"nowhere.speed" = [1]', "nowhere: unknown field"),
        ('metrics = ["reachd"]', "no 'reachd' in its summary"),
        ('scenarios = ["no-such-floor"]', "no such file or preset"),
        ("max_iterations = 5", "no scenario of this sweep takes it"),
        ('controller = "nope"', "unknown arena controller 'nope'"),
        ("seeds = { first = 1, count = 0 }", "seeds"),
        ("grid = 3", "expected a [grid] table"),
        ('metrics = ["builtins:abs"]', "raised TypeError"),
        ('metrics = ["no_such_module:f"]', "cannot use 'no_such_module:f'"),
    ],
)
def test_a_bad_sweep_is_refused_in_one_line_before_any_run(tmp_path, capsys, body, says):
    lines = {"scenarios": 'scenarios = ["zmaze"]', "metrics": 'metrics = ["reached"]', "max_ticks": "max_ticks = 5"}
    for key in lines:
        if body.startswith(key):
            lines[key] = ""
    grid = body.index("[grid]") if "[grid]" in body else len(body)
    file = tmp_path / "bad.toml"
    file.write_text("\n".join([*lines.values(), body[:grid], body[grid:]]))
    assert main(["sweep", str(file), "--out", str(tmp_path / "out"), "--jobs", "1"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("swarm: error: ") and err.count("\n") == 1 and says in err, err
    assert not (tmp_path / "out").exists()


def test_a_grid_preset_sweeps_its_generator_and_agents(tmp_path):
    spec = {"scenarios": ["setup1"], "agents": [2, 3], "max_iterations": 30, "seeds": [1],
            "metrics": ["delivered", "explored_cells", "builtins:len"],
            "grid": {"generator.obstacle_density": [0.1, 0.3]}}  # fmt: skip
    rows = run_sweep(spec, jobs=1, out=tmp_path, progress=False)["rows"]
    assert [(r["generator.obstacle_density"], r["agents"]) for r in rows] == [(0.1, 2), (0.1, 3), (0.3, 2), (0.3, 3)]
    assert (tmp_path / "delivered.png").exists() and (tmp_path / "summary.csv").exists()
    assert all(r["builtins:len"] > 5 for r in rows)  # a metric of yours: module:function(summary)
    preset = load_scenario("setup1")
    assert parse_scenario_data(*scenario_tables("setup1")) == preset  # a preset's tables are the preset
    scenario = replace(preset, generator=replace(preset.generator, obstacle_density=0.3)).with_overrides(
        agents=3, seed=1
    )
    args = argparse.Namespace(record=None, until="foraged", max_iterations=30, json=True)
    summary = run_grid(scenario, args)
    assert [rows[3]["delivered"], rows[3]["explored_cells"]] == [summary["delivered"], summary["explored_cells"]]


def test_a_scenario_error_raised_in_a_worker_reaches_the_parent_whole():
    exc = pickle.loads(pickle.dumps(ScenarioError("f.toml", "metrics", "no 'x'")))
    assert (exc.source, exc.where, str(exc)) == ("f.toml", "metrics", "f.toml: metrics: no 'x'")


def test_dotted_keys_reach_arrays_of_tables_and_user_controllers():
    data = {"group": [{"count": 1}]}
    assign(data, "group.1.count", 3, "f")
    assign(data, "my.pkg:Ctl.gain", 0.5, "f")
    assert data == {"group": [{"count": 3}], "my.pkg:Ctl": {"gain": 0.5}}
    with pytest.raises(ValueError, match="a number from 1 to 1"):
        assign(data, "group.2.count", 1, "f")


def test_the_help_shows_a_sweep_file(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["sweep", "--help"])
    out = capsys.readouterr().out
    assert stop.value.code == 0 and "a sweep file:" in out and '"wander.speed" = [0.4, 0.6, 0.8]' in out
