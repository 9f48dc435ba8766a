"""Both world kinds keep one contract, and one loop over it runs either."""

import numpy as np
import pytest

from agents.controllers.grid.dispatch import step_controller
from swarm.engines.arena import ArenaEngine
from swarm.engines.grid import Engine
from swarm.engines.stepper import step_world
from swarm.scenario import load_scenario
from world_server.arena.world import ArenaWorld
from world_server.contract import World
from world_server.grid.face.layout import controller_kind, controller_params, new_memory
from world_server.grid.world import GridWorld


def test_both_kinds_keep_the_contract():
    assert isinstance(GridWorld(load_scenario("setup2")), World)
    assert isinstance(ArenaWorld(load_scenario("zmaze")), World)


@pytest.mark.parametrize(("ref", "controller", "agents", "seed"), [("setup2", "cmarking", 3, 4), ("maze", "ant", 4, 1)])
def test_the_grid_run_through_the_contract_is_the_compiled_engines_run(ref, controller, agents, seed):
    scenario = load_scenario(ref).with_overrides(agents=agents, controller=controller, seed=seed)
    compiled = Engine(scenario)
    expected = compiled.run(max_iterations=20_000).summary
    world = GridWorld(scenario)
    kind, params, mem = controller_kind(controller), controller_params(scenario), new_memory(agents)
    acts = np.zeros_like(world.acts)

    def decide(perceptions, tick):
        pi, pf = perceptions
        for a in range(agents):
            step_controller(kind, pi[a], pf[a], mem[a], acts[a], params, np.int64(seed), a, tick)
        return acts

    ran = step_world(world, decide, 20_000)
    assert ran == expected["iterations"] and world.tick == ran
    np.testing.assert_array_equal(world.layers, compiled.world.layers)
    np.testing.assert_array_equal(world.pos, compiled.world.pos)


def test_a_snapshot_restores_the_world_it_was_taken_from():
    for world, other in ((GridWorld(load_scenario("setup2")), GridWorld(load_scenario("setup2"))),
                         (ArenaEngine(load_scenario("zmaze")).world, ArenaWorld(load_scenario("zmaze"))),):  # fmt: skip
        if world.kind == "arena":
            world.apply_all(np.full((world.n, 2), 0.05))
        else:
            world.apply_all(world.acts)
        other.restore(world.snapshot())
        assert other.tick == world.tick == 1
        for key, value in world.snapshot().items():
            np.testing.assert_array_equal(other.snapshot()[key], value, err_msg=key)
