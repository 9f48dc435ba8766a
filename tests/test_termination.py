"""No livelock: hundreds of seeded runs of setups 1 and 2 all finish within
the documented bound (docs/cmarking.md): setup 1 within 600,000 / n
iterations, setup 2 within 12,000 / n, for n agents."""

import pytest

from swarm.engines.grid import Engine
from swarm.scenario import load_scenario

BOUND = {"setup1": 600_000, "setup2": 12_000}


@pytest.mark.parametrize(
    ("preset", "agents", "seeds"),
    [("setup1", 1, 15), ("setup1", 2, 15), ("setup1", 5, 30), ("setup1", 10, 40), ("setup1", 20, 40),
     ("setup1", 40, 40), ("setup1", 80, 40), ("setup1", 160, 40)]
    + [("setup2", n, 60) for n in range(1, 9)],
)  # fmt: skip
def test_all_runs_finish_within_the_bound(preset, agents, seeds):
    bound = BOUND[preset] // agents
    for seed in range(1000, 1000 + seeds):
        scenario = load_scenario(preset).with_overrides(agents=agents, seed=seed)
        summary = Engine(scenario).run("foraged", max_iterations=bound).summary
        assert summary["finished"], f"{preset} n={agents} seed={seed}: {summary}"
        assert summary["delivered"] == summary["total"] and summary["in_transit"] == 0


@pytest.mark.parametrize("seed", range(10))
def test_ants_finish_on_open_maps(seed):
    scenario = load_scenario("setup3-25").with_overrides(controller="ant", seed=seed)
    assert Engine(scenario).run("foraged", max_iterations=200_000).finished
