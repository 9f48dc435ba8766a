"""Lemma 4.1, property-based: at every iteration, every marked cell other than
the base has a strictly lower marked neighbour (so descent never gets stuck)."""

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from swarm.engines.grid import Engine
from tests.helpers import lemma41_violations
from world_server.grid.scenario import Generator, Scenario


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    width=st.integers(5, 24),
    height=st.integers(5, 24),
    density=st.sampled_from([0.0, 0.05, 0.2, 0.3, 0.4]),
    resources=st.integers(0, 6),
    agents=st.integers(1, 30),
    controller=st.sampled_from(["marking", "cmarking"]),
    seed=st.integers(0, 2**32),
)
def test_every_marked_cell_has_a_lower_neighbour(width, height, density, resources, agents, controller, seed):
    gen = Generator(width, height, density, min(resources, width * height // 4))
    scenario = Scenario("lemma", "hypothesis", seed=seed, agents=agents, controller=controller,
                        quantity=300, generator=gen)  # fmt: skip
    engine = Engine(scenario)
    for _ in range(150):
        engine.step(1, until="both")
        assert lemma41_violations(engine.world.layers, engine.world.base) == 0, f"tick {engine.tick}"
