"""`swarm bench soak`: its pure parts (memory growth, missing ticks, losses counted), how it finds the run's
processes in /proc (a real child process), and the full 30-minute soak against issue 49's targets
(`-m experiment`).  The quick run is tests/test_registries.py's, as for every benchmark."""

from __future__ import annotations

import subprocess
import sys
import time

import numpy as np
import pytest

from swarm.bench.soak import checks, procs
from swarm.bench.soak.measure import run
from swarm.bench.soak.report import format_soak_bench


def test_growth_is_measured_over_the_last_two_thirds_from_the_medians_near_each_end():
    flat = [(float(t), 1000.0) for t in range(0, 91)]
    assert checks.growth(flat, 90.0, 3.0) == {"start_kb": 1000, "end_kb": 1000, "growth_pct": 0.0}
    # 1000 kB until 40 s, then a straight climb to 1100 kB at 90 s; one outlier near the start is outvoted
    climbing = [(float(t), 1000.0 + max(0, t - 40) * 100 / 50) for t in range(0, 91)]
    climbing[30] = (30.0, 5000.0)
    g = checks.growth(climbing, 90.0, 3.0)
    assert g["start_kb"] == 1000 and 1090 <= g["end_kb"] <= 1100 and 9.0 <= g["growth_pct"] <= 10.0
    assert checks.span(1800.0) == pytest.approx((600.0, 1800.0))  # 30 minutes: the last 20


def test_growth_without_samples_at_either_end_is_not_a_number():
    assert checks.growth([], 90.0, 3.0)["growth_pct"] is None
    assert checks.growth([(80.0, 1000.0), (90.0, 1000.0)], 90.0, 3.0)["growth_pct"] is None  # none near 30 s


def test_missing_ticks_are_those_of_the_played_run_the_recording_lacks():
    assert checks.missing_ticks(np.arange(600), 600) == []
    assert checks.missing_ticks(np.r_[0:256, 512:600], 600) == list(range(256, 512))
    assert checks.missing_ticks(np.arange(599), 600) == [599]


def test_every_kill_must_be_counted_as_a_death_a_replacement_and_its_agents_lost():
    counted = {"agent_processes_died": 3, "agent_processes_replaced": 3, "agents_lost": 6}
    assert checks.losses(counted, kills=3, per_process=2)["all_counted"]
    assert not checks.losses({**counted, "agent_processes_replaced": 2}, kills=3, per_process=2)["all_counted"]
    assert not checks.losses({**counted, "agents_lost": 5}, kills=3, per_process=2)["all_counted"]
    # a live process's agents dropped for missed real-time ticks are losses too, beside the kills'
    beyond = checks.losses({**counted, "agents_lost": 8}, kills=3, per_process=2)
    assert beyond["all_counted"] and beyond["beyond_kills"] == 2
    assert not checks.losses({}, kills=1, per_process=1)["all_counted"]


def test_the_run_s_processes_are_found_by_their_command_line_and_joined_once_they_wrote_their_ids(tmp_path):
    ids = tmp_path / "child.ids"
    cmd = [sys.executable, "-c", "import time; time.sleep(30)", "agent", "--run-id", "soaktest", "--ids-file", str(ids)]
    other = [sys.executable, "-c", "import time; time.sleep(30)", "agent", "--run-id", "another"]
    children = [subprocess.Popen(cmd), subprocess.Popen(other)]
    try:
        time.sleep(0.5)
        (found,) = procs.children("soaktest")
        assert (found.pid, found.role) == (children[0].pid, "agent")
        assert procs.resident_kb(found.pid) > 0
        assert not procs.joined(found)
        ids.write_text("[3]")
        assert procs.joined(found)
    finally:
        for p in children:
            p.kill()
            p.wait()
    assert procs.children("soaktest") == [] and procs.resident_kb(children[0].pid) == 0


@pytest.mark.experiment
@pytest.mark.timeout(45 * 60)  # 30 minutes of ticks, the agents' start, the recording read back
def test_a_30_minute_soak_with_a_kill_every_10_s_keeps_memory_flat_every_tick_and_every_loss(tmp_path):
    result = run(minutes=30.0, kill_every=10.0, out=str(tmp_path))
    print(format_soak_bench(result))
    assert result["losses"]["kills"] >= 170 and result["losses"]["all_counted"], result["losses"]
    assert result["played"] == 36_000 and result["missing_ticks"] == []
    for role in ("world", "launcher"):
        assert result["memory"][role]["growth_pct"] <= checks.TARGET_GROWTH, (role, result["memory"][role])
    assert result["met"]
