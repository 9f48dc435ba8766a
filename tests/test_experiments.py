"""The congestion study (`swarm experiment congestion`): its plan, one real run
of each kind, and the table it computes."""

from __future__ import annotations

import pytest

from swarm.experiments.simonin2007 import paper
from swarm.experiments.simonin2007.tables import CONGESTION_AGENTS, CONGESTION_CAP, EXPERIMENTS, RunSpec, plan, run_one


def test_congestion_plans_ideal_and_physical_runs_under_one_cap():
    specs = plan("congestion", reps=2, seed=5)
    assert len(specs) == len(CONGESTION_AGENTS) * 2 * 2
    assert {(s.agents, s.physics) for s in specs} == {(n, p) for n in CONGESTION_AGENTS for p in ("ideal", "physical")}
    assert {s.seed for s in specs} == {5, 6}
    assert all(s.scenario == "setup1" and s.controller == "cmarking" for s in specs)
    assert {s.max_iterations for s in specs} == {CONGESTION_CAP}
    assert specs[0].physics == "physical" and specs[0].agents == max(CONGESTION_AGENTS)  # longest work first


@pytest.mark.parametrize("physics", ["ideal", "physical"])
def test_a_run_reports_its_bodies(physics):
    row = run_one(RunSpec("congestion", "setup2", 20, 4, "cmarking", physics, 3, 5000))
    assert row["physics"] == physics and row["finished"] and row["wall_seconds"] > 0
    if physics == "ideal":
        assert row["blocked_share"] == 0.0 and row["blocked_moves"] == 0
    else:
        assert 0.0 <= row["blocked_share"] < 1.0 and row["blocked_moves"] >= 0


def _row(agents, physics, iterations, finished=True, share=0.0, moves=0, seconds=1.0):
    return {"agents": agents, "physics": physics, "iterations": iterations, "finished": finished,
            "blocked_share": share, "blocked_moves": moves, "wall_seconds": seconds}  # fmt: skip


def test_congestion_table_puts_the_papers_grid_number_beside_ideal_and_physical():
    rows = []
    for n in CONGESTION_AGENTS:
        rows += [_row(n, "ideal", 1000), _row(n, "ideal", 3000)]
        rows += [_row(n, "physical", 3000, share=0.1, moves=10, seconds=2.0),
                 _row(n, "physical", 20_000, finished=False, share=0.3, moves=30, seconds=8.0)]  # fmt: skip
    summary, md = EXPERIMENTS["congestion"].report(rows)
    first = summary[0]
    assert first["agents"] == CONGESTION_AGENTS[0] and first["paper_mean"] == paper.TABLE1[CONGESTION_AGENTS[0]][0]
    assert first["ideal_mean"] == 2000 and first["physical_mean"] == (3000 + 20_000) / 2
    assert first["physical_over_ideal"] == pytest.approx((3000 + 20_000) / 2 / 2000, abs=1e-3)
    assert first["physical_unfinished"] == 1 and first["ideal_unfinished"] == 0
    assert first["blocked_share"] == pytest.approx(0.2) and first["blocked_moves"] == 20
    assert first["physical_ticks_per_second"] == round((3000 + 20_000) / 10.0)  # all ticks / all seconds
    assert "| 10 | 8697 | 2,000 | 11,500 | 5.75 | 0.200 | 20 |" in md and "1/2 |" in md
