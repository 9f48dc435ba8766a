"""Scenarios: the paper's presets, generation, and clear errors for bad files."""

import numpy as np
import pytest

from swarm.core.errors import ScenarioError
from swarm.scenario import load_scenario, parse_scenario_text


@pytest.mark.parametrize(
    ("ref", "shape", "density", "resources", "quantity", "agents"),
    [("setup1", (40, 40), 0.30, 20, 1000, 10), ("setup2", (20, 20), 0.05, 2, 1000, 1),
     ("setup3-12", (12, 12), 0.05, 20, 2000, 50), ("setup3-200", (200, 200), 0.05, 20, 2000, 50)],
)  # fmt: skip
def test_presets_follow_the_paper(ref, shape, density, resources, quantity, agents):
    s = load_scenario(ref)
    assert (s.q_max, s.agents, s.quantity) == (100, agents, quantity)
    layout = s.layout()
    h, w = shape
    assert layout.shape == shape and layout.base == (h // 2, w // 2)
    assert layout.obstacles.sum() == round(density * (h * w - 1))
    assert not layout.obstacles[layout.base]
    cells = np.argwhere(layout.resources > 0)
    assert len(cells) == resources and (layout.resources[layout.resources > 0] == quantity).all()
    assert (layout.bfs[layout.resources > 0] > 0).all()  # reachable, never the base


def test_generation_depends_only_on_the_seed():
    a, b = (load_scenario("setup1").with_overrides(seed=9).layout() for _ in range(2))
    np.testing.assert_array_equal(a.obstacles, b.obstacles)
    np.testing.assert_array_equal(a.resources, b.resources)


def test_bundled_scenarios_load():
    for name in ("maze", "open"):
        layout = load_scenario(name).layout()
        assert layout.reachable_cells > 10 and layout.resources.sum() > 0


GOOD = 'agents = 3\n[map]\nascii = """\n#####\n#B.R#\n#####\n"""\n'


def _error(text: str) -> str:
    with pytest.raises(ScenarioError) as info:
        parse_scenario_text(text, "bad.toml").layout()
    return str(info.value)


def test_good_minimal_file():
    s = parse_scenario_text(GOOD, "good.toml")
    assert s.agents == 3 and s.layout().resources.sum() == 1000


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("agents = [", "bad.toml: TOML: not valid TOML"),
        ("agents = 3\n", "give exactly one of [map]"),
        (GOOD + "[generator]\nwidth=5\nheight=5\nobstacle_density=0.1\nresources=1\n", "exactly one of"),
        (GOOD.replace("agents = 3", "agents = 0"), "agents: expected 1 to"),
        (GOOD.replace("agents = 3", 'agents = "ten"'), "agents: expected int, got 'ten'"),
        (GOOD.replace("agents = 3", "speed = 3"), "top level: speed: unknown field"),
        (GOOD.replace("agents = 3", 'controller = "bees"'), "controller: unknown 'bees'"),
        (GOOD.replace("agents = 3", "q_max = 0"), "q_max: expected a carrying capacity >= 1"),
        (GOOD.replace("#B.R#", "#B.R##"), "map row 2 (line 5): has 6 cells, expected 5"),
        (GOOD.replace("#B.R#", "#B.X#"), "map row 2 (line 5): column 4: unexpected 'X'"),
        (GOOD.replace("#B.R#", "#B.B#"), "expected exactly one base B, found 2"),
        (GOOD.replace("#B.R#", "#B#R#"), "map row 2 (line 5): column 4: resource R cannot be reached"),
        ("[generator]\nwidth=5\nheight=5\nobstacle_density=0.9\nresources=1\n", "obstacle_density: expected 0 to 0.6"),
        ("[generator]\nwidth=5\nheight=5\nresources=1\n", "generator.obstacle_density: missing"),
        ("[generator]\nwidth=2\nheight=5\nobstacle_density=0.1\nresources=1\n", "generator.width: expected 3 to 4096"),
        (GOOD + "[ant]\ndiffusion = 2.0\n", "ant.diffusion: expected a rate in [0, 1]"),
        (GOOD + "[ant]\ndeposit = nan\n", "ant.deposit: expected a positive amount"),
        (GOOD + "[ant]\nwiggle = 200\n", "ant.wiggle: expected whole degrees from 0 to 180"),
        (GOOD + "[ant]\nthreshold = 1.0\nceiling = 0.5\n", "ant.ceiling: expected an amount above threshold"),
        (GOOD + '[cmarking]\nreturn_on_trail = "repaint"\n', "cmarking.return_on_trail: expected one of mend, descend"),
        (GOOD + '[cmarking]\nat_base = "stay"\n', "cmarking.at_base: expected one of remember, forget"),
        (GOOD + "[cmarking]\nat_base = 1\n", "cmarking.at_base: expected str"),
    ],
)  # fmt: skip
def test_bad_scenarios_say_where_and_what(text, expected):
    assert expected in _error(text)


def test_missing_file_names_presets():
    with pytest.raises(ScenarioError, match="no such file or preset; presets: setup1"):
        load_scenario("does/not/exist.toml")


def test_unknown_preset_size():
    with pytest.raises(ScenarioError, match="setup1 takes no size"):
        load_scenario("setup1-40")
