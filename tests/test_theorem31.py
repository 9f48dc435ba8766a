"""Theorem 3.1: marking agents build the optimal APF (the BFS wavefront)."""

import pytest

from swarm.engines.grid import Engine
from swarm.scenario import load_scenario
from tests.helpers import ascii_scenario, marks_equal_bfs, maze_rows
from world_server.grid.world import L_MARK


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("preset", ["setup1", "setup2", "setup3-25"])
def test_marking_agents_converge_to_bfs_on_random_maps(preset, seed):
    scenario = load_scenario(preset).with_overrides(controller="marking", agents=1 + seed % 5, seed=seed)
    engine = Engine(scenario)
    summary = engine.run("converged", max_iterations=2_000_000).summary
    assert summary["finished"] and summary["apf_optimal"]
    assert marks_equal_bfs(engine.world.layers)
    assert summary["explored_cells"] == summary["reachable_cells"]


@pytest.mark.parametrize("seed", range(8))
def test_marking_agents_converge_to_bfs_in_mazes(seed):
    scenario = ascii_scenario(maze_rows(8, 12, seed), agents=1 + seed % 4, seed=seed, controller="marking")
    engine = Engine(scenario)
    assert engine.run("converged", max_iterations=2_000_000).summary["apf_optimal"]
    assert marks_equal_bfs(engine.world.layers)


@pytest.mark.parametrize("controller", ["marking", "cmarking"])
def test_both_until_forages_and_converges(controller):
    scenario = load_scenario("maze").with_overrides(controller=controller, seed=4)
    summary = Engine(scenario).run("both", max_iterations=2_000_000).summary
    assert summary["finished"] and summary["apf_optimal"] and summary["delivered"] == summary["total"]


def test_convergence_is_monotone_and_never_below_the_truth():
    """Marks only fall, and never below the BFS distance (they are upper bounds)."""
    engine = Engine(load_scenario("setup1").with_overrides(controller="marking", agents=10, seed=2))
    previous = engine.world.layers[L_MARK].copy()
    truth = engine.world.layout.bfs
    for _ in range(300):
        engine.step(5, until="converged")
        marks = engine.world.layers[L_MARK]
        assert (marks <= previous).all()
        reachable = truth >= 0
        assert (marks[reachable] >= truth[reachable]).all()
        previous = marks.copy()
