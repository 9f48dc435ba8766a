"""A user's controller's record() in a distributed run's recording: sent by its agent process on
records/<group> while the world records, shown by shape as in process (swarm.recording.records)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from swarm.engines.arena import ArenaEngine
from swarm.recording.arena import ArenaRecorder
from swarm.scenario import load_scenario
from tests.arena_helpers import rrd_rows
from tests.distributed import run_world
from world_server.arena.face import wire as arena_proto

OUTSIDE = Path(__file__).parent / "outside"


@pytest.fixture(autouse=True)
def outside_on_path(monkeypatch):
    monkeypatch.syspath_prepend(str(OUTSIDE))
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [str(OUTSIDE), os.environ.get("PYTHONPATH")])))


def test_a_distributed_recording_shows_a_users_record_as_the_in_process_one_does(tmp_path):
    scenario = load_scenario("zmaze").with_overrides(controller="circlers:Circler", agents=2, max_ticks=30)
    engine = ArenaEngine(scenario)
    here = tmp_path / "here.rrd"
    recorder = ArenaRecorder(here, engine.world, engine.goals, {"run_id": "here"}, controllers=engine.controllers)
    recorder.close(engine.run(recorder=recorder))
    there = tmp_path / "there.rrd"
    run_world(scenario, "records", [("circlers:Circler", 1, 2)], record=str(there))
    local, distributed = rrd_rows(here), rrd_rows(there)
    mine = {k: n for k, n in local.items() if k.startswith(("controllers/", "world/records/"))}
    assert mine and {k: distributed.get(k) for k in mine} == mine  # series every tick, arrays every 10th


def test_a_record_message_carries_numbers_and_arrays_and_refuses_anything_else():
    record = {"n": 3, "flag": True, "v": np.arange(3), "note": "text", "cube": np.zeros((2,) * 3)}
    values = arena_proto.record_values(record, tick=10)
    assert set(values) == {"n", "flag", "v"}
    assert set(arena_proto.record_values({"n": 3, "v": np.arange(3)}, tick=11)) == {"n"}  # arrays every 10th tick
    got = arena_proto.parse_record(arena_proto.record_message(10, 1, values))
    assert (got.tick, got.agent, got.values["n"]) == (10, 1, 3.0) and got.values["v"].tolist() == [0.0, 1.0, 2.0]
    assert arena_proto.record_message(0, 0, {"big": np.zeros((400, 400))}) is None  # over MAX_RECORD_BYTES
    forged = arena_proto.pack({"type": "record", "family": "arena", "tick": 1, "agent": 0, "record": b"\x93\x01"})
    assert isinstance(arena_proto.parse_record(forged), arena_proto.Rejected)


def test_a_record_of_arrays_alone_does_not_hold_the_runs_end_for_the_deadline(tmp_path):
    """braitenberg's record() is one array, sent every 10th tick: the last tick (24) sends none, and its
    action says so, so the world ends the run without waiting its 30 s deadline for a record."""
    scenario = load_scenario("zmaze").with_overrides(controller="braitenberg", agents=2, max_ticks=25)
    there = tmp_path / "there.rrd"
    summary, _ = run_world(scenario, "arrays", [("braitenberg", 1, 2)], deadline=30.0, record=str(there))
    assert summary["ticks"] == 25 and summary["wall_seconds"] < 15.0, summary["wall_seconds"]
    rows = rrd_rows(there)
    assert all(rows[f"controllers/{a}/bars/wheels"] == 3 for a in (0, 1))  # ticks 0, 10 and 20
    acts = arena_proto.parse_acts(arena_proto.actions(7, [0, 1], np.zeros((2, 3)), records=[1]))
    assert acts.records == (1,) and arena_proto.parse_acts(arena_proto.actions(8, [0], np.zeros((1, 3)))).records == ()
    bad = arena_proto.pack({"type": "act", "family": "arena", "tick": 1, "agents": [0],
                            "wheels": np.zeros(2).tobytes(), "records": ["x"]})  # fmt: skip
    assert isinstance(arena_proto.parse_acts(bad), arena_proto.Rejected)
