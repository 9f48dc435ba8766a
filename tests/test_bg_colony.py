"""A colony of bg animats: the map and what its places hold
shared over the `map` key space, frames aligned by the places two animats
share, the same colony in both runtimes, and the colony experiment."""

import json

import numpy as np
import pytest

from agents.controllers.arena import deliver
from agents.controllers.bg.colony import ColonyMap
from agents.controllers.bg.params import NavParams
from agents.controllers.bg.places import Navigator
from agents.controllers.bg.senses import RESOURCES
from swarm.core.wire import pack
from swarm.engines.arena import ArenaEngine
from swarm.experiments.girard2005.colony import colony_scenario
from tests.arena_helpers import MapSharer, resumed_pair


def _place(k: int) -> tuple[np.ndarray, np.ndarray]:
    return np.full(36, 20 + 45 * k, np.uint8), np.full(8, 1.0 + 1.0 * k)


def _animat(agent: int, places: range) -> tuple[Navigator, ColonyMap]:
    """An animat that drove east along a corridor through `places` (0.3 m apart), from its own frame's origin."""
    nav = Navigator(NavParams(), 0, agent, RESOURCES)
    colony = ColonyMap(nav, agent)
    for n, k in enumerate(places):
        nav.move(0.3 if n else 0.0, 0.0)
        colony.adopt(nav.observe(*_place(k), 0.0))
        for _ in range(5):
            nav.observe(*_place(k), 0.0)
    return nav, colony


def test_places_two_animats_share_align_their_frames_and_the_others_come_over():
    a, ca = _animat(0, range(0, 4))  # places 0-3; a started at place 0
    _, cb = _animat(1, range(2, 6))  # places 2-5; b started at place 2, 0.6 m east of a's start
    ca.receive(1, json.loads(json.dumps(cb.publish())))
    assert ca.shared.merged == 2 and ca.shared.added == 2  # places 2 and 3 are a's own; 4 and 5 are new
    offset, aliases = ca.shared.frames[1]
    np.testing.assert_allclose(offset, [0.6, 0.0], atol=1e-9)
    assert aliases == 2
    xs = sorted(round(float(n.position[0]), 6) for n in a.map.nodes)
    assert xs == [0.0, 0.3, 0.6, 0.9, 1.2, 1.5]  # b's places 4 and 5 in a's frame
    assert len(a.born) == len(a.assoc["Ep"]) == 6  # the navigator grew with the map
    route = a.map.route(3, int(np.argmax([n.position[0] for n in a.map.nodes])))
    assert len(route) == 3  # from a's last place on over b's link 3-4 and 4-5


def test_what_a_place_holds_travels_and_the_latest_news_wins_without_echo():
    a, ca = _animat(0, range(0, 4))
    b, cb = _animat(1, range(0, 4))
    cb.receive(0, ca.publish())
    ca.receive(1, cb.publish())  # the same four places: every one an alias both ways
    assert len(a.map.nodes) == len(b.map.nodes) == 4
    for _ in range(40):
        a.learn({"Ep": True}, {"Ep": True}, 0.25)  # a at place 3 (its belief), food there
    assert a.assoc["Ep"][3] > 0.99
    cb.receive(0, ca.publish())
    assert b.assoc["Ep"][3] > 0.99 and cb.heard == 1
    assert "holds" not in (cb.publish() or {})  # what b heard is not sent back
    b.map.belief = np.eye(4)[3]
    for _ in range(30):  # b at place 3, no food in sight: it forgets a little
        b.learn({"Ep": False}, {"Ep": False}, 0.25)
    told = cb.publish()
    assert told is not None and len(told["holds"]) == 1
    ca.receive(1, told)
    assert a.assoc["Ep"][3] == pytest.approx(b.assoc["Ep"][3], abs=1e-4) and a.assoc["Ep"][3] < 0.9


@pytest.mark.parametrize(
    "holds", [[[0, 1, 0.5]], [[0, 1, 0.5, 2.0, 0.0]], [[0, 1, float("nan"), 0.0, 0.0]], "x", [["a", 1, 0, 0, 0]]]
)
def test_malformed_holds_are_refused_and_nothing_of_them_is_merged(holds):
    a, ca = _animat(0, range(0, 2))
    _, cb = _animat(1, range(3, 5))
    data = cb.publish()
    data["holds"] = holds
    nodes = len(a.map.nodes)

    assert deliver([MapSharer(ca), MapSharer(cb)], [0, 1], [(1, "map", pack(data))]) == 1
    assert len(a.map.nodes) == nodes and ca.shared.added == 0


def test_a_sharing_colony_resumes_bit_for_bit():
    a, b = resumed_pair(colony_scenario(2, True, 1, max_ticks=240), 120)
    np.testing.assert_array_equal(a.world.pose, b.world.pose)
    assert [c.snapshot() for c in a.controllers] == [c.snapshot() for c in b.controllers]
    assert a.controllers[0].colony.shared.added > 0 and a.refused_shared == 0


@pytest.mark.parametrize(("processes", "per_process"), [(2, 1), (1, 2)])
def test_lockstep_colony_equals_in_process_bit_for_bit(processes, per_process):
    from tests.distributed import run_world

    scenario = colony_scenario(2, True, 3, max_ticks=200)
    engine = ArenaEngine(scenario)
    expected = engine.run()
    assert all(r["map"]["from_others"] > 0 for r in expected["robots"])  # each has the other's places
    summary, world = run_world(scenario, f"bg-colony-{processes}", [("bg", processes, per_process)], deadline=90.0)
    np.testing.assert_array_equal(world.pose, engine.world.pose)
    assert [r["shared"] for r in summary["robots"]] == [r["shared"] for r in expected["robots"]]
    assert summary["rejected_messages"] == 0


def test_the_colony_experiment_writes_its_table(tmp_path):
    from swarm.experiments.girard2005.colony import run_colony_experiment

    result = run_colony_experiment("bg-colony", (1, 2), 2, 2, 0, tmp_path, progress=False, max_ticks=120)
    assert result["runs"] == 6  # one alone twice, two with and without sharing twice each
    for name in ("runs.csv", "summary.csv", "table.md", "plot.png"):
        assert (tmp_path / name).exists(), name
    text = (tmp_path / "table.md").read_text()
    assert "| 2 | yes | 2 |" in text and "| 2 | no | 2 |" in text and "U = " in text


def test_the_nest_holds_eight_animats_clear_of_walls_and_of_each_other():
    from swarm.experiments.girard2005.colony import NEST
    from swarm.scenario import load_scenario
    from world_server.arena.scenario import clearance_at

    s = colony_scenario(8, True, 0)
    xy = np.array(NEST)
    assert (clearance_at(xy, s.wall_rects(), s.wall_segments()) > 0.15 + 0.1).all()
    gaps = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))
    assert gaps[~np.eye(8, dtype=bool)].min() >= 0.6 - 1e-9
    bundled = load_scenario("bg-colony")  # the file's four starts are the nest's first four
    np.testing.assert_allclose(bundled.start_poses()[:, :2], xy[:4])
    assert ArenaEngine(colony_scenario(8, True, 0, max_ticks=3)).step(3) == 3
