"""The fingerprint controller (Tapus et al. 2006): features, circular alignment
with uncertainty, the generic topological map with Markov localization, and
the controller on the office floor."""

from __future__ import annotations

import itertools
import json
import math
import subprocess
import sys
from functools import cache

import numpy as np
import pytest

from agents.controllers.fingerprint.align import (
    C,
    Matcher,
    N,
    V,
    cyclic_cost,
    cyclic_cost_exact,
    from_string,  # fmt: skip
    paper_length,
    to_string,
)
from agents.controllers.fingerprint.features import camera_features, fingerprint, laser_corners
from agents.controllers.fingerprint.params import AlignParams, FeatureParams
from agents.controllers.navigation.params import MapParams
from agents.controllers.navigation.topomap import Link, TopoMap
from swarm.core.errors import ScenarioError
from swarm.scenario import load_scenario


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "swarm", *args], capture_output=True, text=True, timeout=600)


@cache
def office():
    return load_scenario("office")


def sensed(x: float, y: float, theta: float = 0.0, noise: str = "low"):
    from swarm.cli_arena import sense

    r = sense(office().with_overrides(noise=noise), (x, y, theta))
    return fingerprint(np.array(r["camera_rgb"]), np.array(r["camera_range"]), np.array(r["laser"]), 8.0,
                       FeatureParams())  # fmt: skip


# ------------------------------------------------------------------ strings


def test_strings_round_trip_in_the_papers_notation():
    text = "clfvnvcfnvncvnnvcvBnvBccE".replace("l", "L").replace("f", "F")  # the paper's example, hues upper case
    codes = from_string(text)
    assert to_string(codes) == text
    assert paper_length(codes) == len(text)
    assert (codes == N + 1).sum() == 1 and (codes == N).sum() == 4  # a run "nn" is one symbol of the alignment
    with pytest.raises(ValueError, match="'x' is not a feature"):
        from_string("vcx")


# ---------------------------------------------------------------- features


def test_a_colour_patch_is_a_hue_letter_at_its_bearing_with_edges_on_both_sides():
    rgb = np.full((360, 3), 200, np.uint8)
    rgb[85:96] = (0, 0, 255)  # blue, centred on 90 degrees
    codes, bearings = camera_features(rgb, np.full(360, 3.0), FeatureParams())
    hue = codes[codes < V]
    assert len(hue) == 1 and to_string(hue) == "K"  # blue's hue 240 deg, bin 10 of 16
    assert math.degrees(bearings[codes < V][0]) == pytest.approx(90, abs=1)
    edges = np.degrees(bearings[codes == V])
    assert sorted(edges) == pytest.approx([84.5, 95.5])  # the boundaries between 84|85 and 95|96


def test_the_laser_sees_the_four_corners_of_a_square_room():
    beams = 360
    angle = np.arange(beams) * 2 * math.pi / beams
    half = 2.0  # a 4 m square room, the robot at its centre
    ranges = half / np.maximum(np.abs(np.cos(angle)), np.abs(np.sin(angle)))
    corners = np.degrees(laser_corners(ranges, 8.0, FeatureParams()))
    assert len(corners) == 4
    assert sorted(np.round(corners) % 360) == [45, 135, 225, 315]


def test_a_real_fingerprint_has_every_kind_of_feature():
    f = sensed(2.0, 9.0)
    text = str(f)
    assert {"v", "c", "n"} <= set(text) and any(ch.isupper() for ch in text)
    assert 15 <= f.length <= 80


# ---------------------------------------------------------------- matching


def test_a_fingerprint_matches_itself_at_every_rotation():
    m = Matcher()
    for f in (sensed(2.0, 9.0), sensed(6.0, 3.0, 1.0), sensed(20.0, 6.0)):
        for r in range(len(f.codes)):
            rotated = np.roll(f.codes, r)
            assert m.cost(f.codes, rotated) == 0.0
            assert m.cost(f.codes, rotated, exact=True) == 0.0
            assert m.probability(f.codes, rotated) > 0.98


def test_one_missing_feature_costs_less_than_one_wrong_feature():
    m = Matcher()
    f = sensed(10.0, 9.4).codes
    for k in np.flatnonzero(f < N):  # every feature in turn
        missing = np.delete(f, k)
        wrong = f.copy()
        wrong[k] = C if f[k] != C else V
        assert m.cost(f, missing, exact=True) < m.cost(f, wrong, exact=True)


def test_a_place_seen_from_nearby_matches_it_better_than_another_place():
    m = Matcher()
    here = sensed(2.0, 9.0)
    near = sensed(2.2, 9.3, 0.6)  # 36 cm away, turned 34 degrees
    for other in (sensed(6.0, 2.6), sensed(10.0, 9.4), sensed(14.0, 6.0)):  # another room, a room alike, the corridor
        assert m.probability(here.codes, near.codes) > m.probability(here.codes, other.codes)
    assert m.probability(here.codes, near.codes) > 0.5 > m.probability(here.codes, sensed(10.0, 9.4).codes)


def test_the_one_pass_kernel_is_a_real_alignment_and_exact_on_neighbouring_places():
    """Never below the exact minimum over rotations (it is the cost of one
    rotation's alignment), and equal to it for fingerprints of one place."""
    m = Matcher()
    prints = [sensed(2.0 + 0.1 * k, 8.5 + 0.1 * k, 0.3 * k) for k in range(6)]
    prints += [sensed(6.0, 3.0), sensed(22.0, 6.0)]
    equal = 0
    for a in prints:
        for b in prints:
            fast = cyclic_cost(a.codes, b.codes, m.sub, m.gap)
            exact = cyclic_cost_exact(a.codes, b.codes, m.sub, m.gap)
            assert fast >= exact
            equal += fast == exact
    near = [(a, b) for a in prints[:6] for b in prints[:6]]
    near_equal = sum(cyclic_cost(a.codes, b.codes, m.sub, m.gap) == cyclic_cost_exact(a.codes, b.codes, m.sub, m.gap)
                     for a, b in near)  # fmt: skip
    assert near_equal >= 0.8 * len(near)


def test_localizing_against_a_packed_map_equals_matching_node_by_node():
    from agents.controllers.fingerprint.signatures import pack

    m = Matcher()
    nodes = [sensed(x, y) for x, y in ((2, 9), (6, 3), (10, 9.4), (14, 6), (26, 8))]
    query = sensed(2.1, 9.2, 0.4)
    packed = m.against(query.codes, *pack([f.codes for f in nodes]))
    one_by_one = [m.probability(query.codes, f.codes) for f in nodes]
    assert packed == pytest.approx(one_by_one)
    assert int(np.argmax(packed)) == 0


def test_the_side_by_side_kernel_equals_the_node_by_node_one_cell_for_cell():
    """localize_costs runs LANES nodes at once, sorted by length, the last batch padded: every
    cost must still be cyclic_cost's, for empty nodes, an empty query and a map not a multiple of LANES."""
    from agents.controllers.fingerprint.align import LANES, SYMBOLS, localize_costs
    from agents.controllers.fingerprint.signatures import pack

    m = Matcher()
    rng = np.random.default_rng(11)
    nodes = [rng.integers(0, SYMBOLS, rng.integers(0, 60)).astype(np.int8) for _ in range(3 * LANES + 5)]
    nodes[7] = nodes[7][:0]
    codes, offsets, _ = pack(nodes)
    for query in (rng.integers(0, SYMBOLS, 40).astype(np.int8), nodes[3][::-1].copy(), np.zeros(0, np.int8)):
        expected = [cyclic_cost(query, b, m.sub, m.gap) for b in nodes]
        assert localize_costs(query, codes, offsets, m.sub, m.gap).tolist() == expected
    assert localize_costs(nodes[0], *pack([])[:2], m.sub, m.gap).tolist() == []


def test_the_probability_calibration_recovers_a_known_logistic():
    from swarm.experiments.tapus2006.fingerprint import fit_logistic

    rng = np.random.default_rng(3)
    d = rng.uniform(0, 1.0, 20000)  # classes about equally common, as the fit weighs them
    same = rng.uniform(size=d.size) < 1 / (1 + np.exp((d - 0.5) / 0.1))
    centre, width = fit_logistic(d, same)
    assert centre == pytest.approx(0.5, abs=0.03) and width == pytest.approx(0.1, abs=0.02)


def test_align_params_refuse_unknown_fields():
    with pytest.raises(ValueError, match="unknown field 'gap'"):
        AlignParams.from_table({"gap": 1})


# ------------------------------------------------------------ topological map


class Labels:
    """A toy place signature: an observation is a place label, seen right with
    probability 0.7, else as a look-alike (the labels 'a' and 'b' alias)."""

    def likelihoods(self, observation, means):
        return np.array([0.9 if observation == m else (0.6 if {observation, m} == {"a", "b"} else 0.05)
                         for m in means])  # fmt: skip

    def mean(self, members):
        values, counts = np.unique(members, return_counts=True)
        return str(values[np.argmax(counts)])


def corridor_map() -> TopoMap:
    """Places a, x, b, y along a line, 2 m apart, three observations each."""
    m = TopoMap(Labels(), MapParams(theta=0.3))
    pos = 0.0
    for label in "axby":
        for _ in range(3):
            m.observe(label, np.array([pos, 0.0]), np.array([0.5, 0.0]))
            pos += 0.5
        pos += 0.5
    return m


def test_mapping_makes_one_node_per_place_with_odometry_links():
    m = corridor_map()
    assert [n.mean for n in m.nodes] == list("axby")
    assert set(m.links) == {(0, 1), (1, 2), (2, 3)}
    link = m.links[(1, 2)]
    # from the first node's centre when it was left (0.5) to where the robot entered the next (2.0)
    assert link.distance == pytest.approx(1.5) and link.direction == pytest.approx(0.0)
    assert m.route(0, 3) == [0, 1, 2, 3] and m.route(3, 0) == [3, 2, 1, 0]


def test_the_markov_filter_tells_apart_places_that_look_alike():
    """'a' and 'b' look alike: matching alone cannot say which; the belief,
    carried along the links by odometry, can."""
    m = corridor_map()
    m.belief = np.eye(4)[0]  # known start: at a
    walk = [("a", 0.0), ("x", 2.0), ("b", 2.0), ("b", 0.5)]
    for label, moved in walk:
        for _ in range(2 if moved else 1):
            like, belief = m.localize(label, np.array([moved / 2 if moved else 0.0, 0.0]))
    assert like[0] == 0.6 and like[2] == 0.9  # matching alone: b over a, but not by much
    assert int(np.argmax(belief)) == 2 and belief[2] > 0.8  # the filter: b, surely


def test_a_sharper_correction_brings_a_belief_back_from_a_look_alike_place_sooner():
    """The belief sits on 'a' while the robot stands at 'b', which looks like it (P 0.6 against 0.9):
    weighing nodes by P ** 2 (the fingerprint controller's sharpness) moves it to 'b' in fewer views."""
    from dataclasses import replace

    def views_until_right(sharpness: float) -> int:
        m = corridor_map()
        m.params = replace(m.params, sharpness=sharpness)
        m.belief = np.eye(4)[0]  # sure, and wrong: at a
        for views in range(1, 50):
            _, belief = m.localize("b", np.zeros(2))  # standing still at b
            if int(np.argmax(belief)) == 2:
                return views
        return 50

    plain, sharp = views_until_right(1.0), views_until_right(2.0)
    assert sharp < plain < 50


def _dark_walk(localize) -> list[tuple[float, int]]:
    """From a known start at 'a', walk the corridor in the dark (views that match no node better than another):
    (true position, believed node) after each step of 0.25 m."""
    out, pos = [], 0.0
    localize("a", np.zeros(2))  # the lights are on at the start
    while pos < 7.0:
        pos += 0.25
        out.append((pos, int(np.argmax(localize("dark", np.array([0.25, 0.0]))))))
    return out


def test_the_grid_belief_follows_the_odometry_where_the_views_say_nothing():
    """Places a, x, b, y along a corridor; in the dark only odometry can say where the robot is.
    On the map's odometric grid the belief moves with it, node by node; over the links alone a
    node is left at a constant rate per view, wherever in the node the robot is."""
    from agents.controllers.navigation.gridbelief import GridBelief
    from agents.controllers.navigation.params import GridParams

    m = corridor_map()  # a at x 0-1, x at 2-3, b at 4-5, y at 6-7 (observations every 0.5 m)
    grid = GridBelief(m, GridParams(cell=0.1))

    def on_grid(label, moved):  # in the dark a view favours no node, and no place off the map either
        like = m.signatures.likelihoods(label, m.means()) if label != "dark" else np.full(4, grid.p.off_map)
        return grid.update(like, moved)

    def over_links(label, moved):
        return m.localize(label, moved)[1]

    def node_at(x: float) -> int:
        return min(3, int((x + 0.5) // 2))

    away = [(x, b) for x, b in _dark_walk(on_grid) if abs((x + 0.5) % 2 - 1.0) < 0.7 and x <= 7.0]
    assert away and all(b == node_at(x) for x, b in away)  # right wherever the robot is not near a boundary
    m.belief = np.zeros(0)
    wrong = [(x, b) for x, b in _dark_walk(over_links) if abs((x + 0.5) % 2 - 1.0) < 0.7 and b != node_at(x)]
    assert wrong  # the links alone lose count in the dark


def test_a_grid_belief_is_saved_and_restored_exactly():
    from agents.controllers.navigation.gridbelief import GridBelief

    m = corridor_map()
    a = GridBelief(m)
    for label in "aaxx":
        a.update(m.signatures.likelihoods(label, m.means()), np.array([0.37, 0.0]))
    b = GridBelief(m)
    b.restore(json.loads(json.dumps(a.to_data())))
    for label in "xbb":
        like = m.signatures.likelihoods(label, m.means())
        assert np.array_equal(a.update(like, np.array([0.37, 0.0])), b.update(like, np.array([0.37, 0.0])))
    with pytest.raises(ValueError, match="cells saved"):
        b.restore({"belief": [1.0], "residual": [0.0, 0.0]})
    with pytest.raises(ValueError, match="seen_at"):
        GridBelief(TopoMap(Labels()))


def test_a_loop_is_closed_through_localization():
    m = corridor_map()
    nodes = len(m.nodes)
    # back the way it came: y, b, x, a again
    for label in "ybxa":
        for _ in range(3):
            m.observe(label, np.array([0.0, 0.0]), np.array([-0.5, 0.0]))
    assert len(m.nodes) == nodes  # no place added twice
    assert m.closures >= 3


def test_a_link_keeps_the_mean_of_the_displacements_it_was_driven_with():
    m = corridor_map()
    m._link(0, 1)  # driven again between the nodes' centres (0.5 and 2.5): the mean of 1.5 and 2.0
    assert m.links[(0, 1)].count == 2
    assert m.links[(0, 1)].distance == pytest.approx(1.75)
    assert isinstance(m.links[(0, 1)], Link)
    assert m.route(0, 0) == [0]


# --------------------------------------------------------------- controller


@cache
def mapping_tour():
    from swarm.experiments.tapus2006.fingerprint import drive_tour, tour_scenario

    s = tour_scenario("office", "mapping", "low", 0)
    return s, drive_tour(s)


def test_the_mapping_tour_takes_about_500_fingerprints_and_maps_every_place_it_passes():
    from swarm.experiments.tapus2006.fingerprint import judge_map, places

    s, run = mapping_tour()
    judged = judge_map(run, places(s))
    assert run["finished"]
    assert 450 <= judged["fingerprints"] <= 530  # the paper: 500 over 75 m
    assert judged["places_with_node"] == judged["places_visited"] == 12
    assert 12 <= judged["nodes"] <= 30  # the paper: 20 on its floor
    assert judged["purity"] > 0.65


def test_a_room_revisit_counts_as_closed_when_it_joins_the_nodes_made_before():
    from swarm.experiments.tapus2006.fingerprint import first_use, room_revisits

    place = np.array([0, 0, 0, 1, 1, 1, 0, 0, 0, 1])  # room 0, corridor 1, room 0 again
    rooms = np.array([True, False])

    def revisits(believed: list[int], where: np.ndarray) -> tuple[int, int]:
        return room_revisits(place, first_use(np.array(believed)), where)

    assert revisits([0, 0, 0, 1, 1, 1, 0, 0, 2, 1], rooms) == (1, 1)
    assert revisits([0, 0, 0, 1, 1, 1, 2, 2, 2, 1], rooms) == (1, 0)  # a new node: not closed
    assert revisits([0, 0, 0, 1, 1, 1, 0, 0, 0, 1], ~rooms) == (0, 0)  # the corridor's second visit is one print


def _hand_run(xs: list[float], joined: list[int]) -> dict:
    """A hand-made mapping run along y = 1: true x per fingerprint, the node each joined (no folds)."""
    joined_ = np.array(joined, np.int64)
    return {"truth": np.array([[x, 1.0, 0.0] for x in xs]), "believed": joined_, "joined": joined_,
            "nodes_after": np.maximum.accumulate(joined_) + 1, "size": int(joined_.max()) + 1,
            "map": {"nodes": [{}] * (int(joined_.max()) + 1), "links": []}}  # fmt: skip


HAND_ZONES = [("room-a", (0.0, 0.0, 2.0, 2.0)), ("corridor", (2.0, 0.0, 10.0, 2.0)), ("room-b", (10.0, 0.0, 12.0, 2.0))]


def test_an_aliased_node_is_right_only_at_its_own_place():
    from swarm.experiments.tapus2006.fingerprint import aliased_nodes, localization_counts, right_nodes

    # node 0: three fingerprints in room a and one in room b, 10 m away (more than the corridor's 8.2 m
    # diagonal): aliased, its place room a; node 1 in room b beside that one
    mapped = _hand_run([1.0, 1.1, 1.2, 11.0, 11.2, 11.3], [0, 0, 0, 0, 1, 1])
    aliased = aliased_nodes(mapped, HAND_ZONES)
    assert aliased == {0: 0}
    assert right_nodes(mapped, np.array([1.0, 1.0]), aliased, HAND_ZONES) == {0}
    assert right_nodes(mapped, np.array([11.0, 1.0]), aliased, HAND_ZONES) == {1}  # wrong at the far end
    assert right_nodes(mapped, np.array([11.0, 1.0])) == {0, 1}  # the loose rule: right at both ends
    loc = {"truth": np.array([[1.0, 1.0, 0.0], [11.0, 1.0, 0.0]]), "matched": np.array([0, 0]),
           "believed": np.array([0, 0]), "believed_links": np.array([0, 1]),
           "likelihoods": [np.array([0.9, 0.1])] * 2}  # fmt: skip
    c = localization_counts(mapped, loc, HAND_ZONES)
    assert (c["aliased_nodes"], c["on_map"]) == (1, 2)
    assert (c["match_right"], c["markov_right"], c["links_right"]) == (1, 1, 2)
    assert (c["match_right_loose"], c["markov_right_loose"], c["links_right_loose"]) == (2, 2, 2)
    assert c["missed_rank2"] == 1  # at room b the right node, 1, came second


def test_loop_closures_are_judged_true_or_false_and_revisits_recalled():
    from swarm.experiments.tapus2006.fingerprint import closure_events, closure_scores, revisits_recalled

    xs = [1.0] * 3 + [5.0] * 3 + [1.0] * 3 + [5.0] * 3 + [11.0] * 3  # room a, corridor, a, corridor, room b
    run = _hand_run(xs, [0, 0, 0, 1, 1, 1, 0, 0, 0, 1, 1, 1, 0, 0, 0])
    assert closure_events(run, HAND_ZONES) == (3, 2)  # back into room a and the corridor: true; room b onto a: false
    assert revisits_recalled(run, HAND_ZONES) == (1, 1)  # room a seen again, on its old node
    scores = closure_scores(run, HAND_ZONES)
    assert (scores["closure_precision"], scores["closure_recall"]) == (0.6667, 1.0)
    missed = _hand_run(xs, [0, 0, 0, 1, 1, 1, 2, 2, 2, 1, 1, 1, 3, 3, 3])  # room a again on a new node
    assert closure_events(missed, HAND_ZONES) == (1, 1)
    assert revisits_recalled(missed, HAND_ZONES) == (1, 0)
    for x, true in ((1.0, 1), (11.0, 0)):  # a young node 2 folded into node 0, in room a (true), in room b (false)
        folded = _hand_run([1.0] * 3 + [5.0] * 3 + [x] * 3, [0, 0, 0, 1, 1, 1, 2, 0, 0])
        folded["believed"] = np.array([0, 0, 0, 1, 1, 1, 0, 0, 0])  # node 2 stands for node 0
        assert closure_events(folded, HAND_ZONES) == (1, true)


def test_the_floors_place_graph_joins_places_through_doors_and_the_corridor_only():
    from swarm.experiments.tapus2006.fingerprint import link_topology, place_graph, places
    from swarm.scenario import load_scenario

    s = load_scenario("office")
    index = {name: k for k, (name, _) in enumerate(places(s))}
    graph = place_graph(s)
    assert len(graph) == 16 + 3  # every room's door onto the corridor, the corridor's four zones in a row
    assert frozenset((index["room_n0"], index["corridor_0"])) in graph
    assert frozenset((index["corridor_0"], index["corridor_1"])) in graph
    assert frozenset((index["room_n0"], index["room_n1"])) not in graph  # a wall, no door
    run = _hand_run([1.0, 5.0, 11.0, 6.0], [0, 1, 2, 3])  # room a, corridor, room b, corridor
    run["map"]["links"] = [[0, 1], [1, 3], [3, 2], [0, 2]]
    hand = {frozenset((0, 1)), frozenset((1, 2))}
    assert link_topology(run, HAND_ZONES, hand) == {"links_same_place": 1, "links_adjacent": 2,
                                                    "links_not_adjacent": 1}  # fmt: skip


def _polyline(points, step: float = 0.05) -> np.ndarray:
    """Points every `step` along a route's waypoints."""
    pts = np.asarray(points, float)
    out = [a + (b - a) * t for a, b in itertools.pairwise(pts)
           for t in np.arange(0, 1, step / max(float(np.hypot(*(b - a))), 1e-9))]  # fmt: skip
    return np.array([*out, pts[-1]])


@pytest.mark.parametrize("floor", ["office", "office-l"])
def test_each_floors_new_path_keeps_to_lines_of_its_own_and_starts_elsewhere(floor):
    """The paper's second tour was "a new path": ours starts away from the mapping tour's ends and keeps
    off its lines but for doorways and crossings, while `localize` (where a floor has one to compare)
    follows them."""
    from swarm.experiments.tapus2006.fingerprint import retracing

    routes = load_scenario(floor).routes
    mapping, new = _polyline(routes["mapping"]), _polyline(routes["new-path"])
    retraced, gap = retracing(mapping, new)
    assert retraced / len(new) < 0.2 and gap > 0.4, (retraced / len(new), gap)
    assert min(math.dist(routes["new-path"][0], routes["mapping"][k]) for k in (0, -1)) > 5.0
    if floor == "office":
        old, old_gap = retracing(mapping, _polyline(routes["localize"]))
        assert old / len(_polyline(routes["localize"])) > 0.5 and old_gap < 0.1


def test_retracing_counts_a_tours_points_near_the_mapping_tour():
    from swarm.experiments.tapus2006.fingerprint import retracing

    mapped = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    assert retracing(mapped, np.array([[0.05, 0.0], [1.0, 0.5], [2.0, 2.0]])) == (1, 0.5)
    assert retracing(mapped, np.empty((0, 2)))[0] == 0


def test_a_floor_without_a_localization_tour_is_refused_in_one_line(tmp_path):
    from swarm.experiments.tapus2006.fingerprint import run_fingerprint_experiment, second_tours

    assert second_tours(load_scenario("office")) == ("new-path", "localize", "localize-off-map")
    from swarm.scenario import BUNDLED_DIR

    text = (BUNDLED_DIR / "office.toml").read_text().split("[routes]")
    mapping = next(line for line in text[1].splitlines() if line.startswith("mapping = "))
    rest = text[1].split("\n[[group]]", 1)[1]
    floor = tmp_path / "mapping-only.toml"
    floor.write_text(text[0] + "[routes]\n" + mapping + "\n\n[[group]]" + rest)
    with pytest.raises(ScenarioError, match="no localization tour; fingerprint-localize needs one of 'new-path'"):
        run_fingerprint_experiment("fingerprint-localize", str(floor), 1, 1, 0, tmp_path / "out", progress=False)
    from swarm.experiments.tapus2006.robustness import run_robustness_experiment

    with pytest.raises(ScenarioError, match="no localization tour; fingerprint-robustness needs one of 'new-path'"):
        run_robustness_experiment("fingerprint-robustness", str(floor), 1, 1, 0, tmp_path / "out", progress=False)
    assert not (tmp_path / "out").exists()


def test_localization_on_the_second_tour_beats_matching_alone_and_chance():
    from swarm.experiments.tapus2006.fingerprint import localize_job

    row = localize_job(("office", "low", 0, "localize"))
    assert row["fingerprints"] >= 1000 and row["on_map"] >= 0.95 * row["fingerprints"]  # it stays on the map
    assert row["retraced"] > 0.5 * row["fingerprints"] and row["gap_median_m"] < 0.1  # along the mapping lines
    assert row["match_correct"] > 5 * row["chance"]  # matching alone well above chance
    assert row["links_markov_correct"] > row["match_correct"] + 0.03  # a filter clearly above matching alone
    assert row["markov_correct"] >= 0.98 and row["markov_correct"] > row["links_markov_correct"]  # the grid more


def test_a_restored_localizing_controller_goes_on_exactly_as_the_one_it_was_taken_from():
    from swarm.engines.arena import ArenaEngine
    from swarm.experiments.tapus2006.fingerprint import tour_scenario
    from world_server.arena.scenario import controller_params

    s = tour_scenario("office", "localize", "low", 1000)
    params = controller_params(s, 0)
    params["fingerprint"] = {**params.get("fingerprint", {}), "mode": "localize"}
    params["topomap"] = mapping_tour()[1]["map"]
    a, b = ArenaEngine(s), ArenaEngine(s)
    a.controllers[0].reset(s.seed, 0, params)
    a.step(300)
    state = json.loads(json.dumps(a.controllers[0].snapshot()))
    b.world.restore(a.world.snapshot())
    b.controllers[0].reset(s.seed, 0, params)
    b.controllers[0].restore(state)
    a.step(200)
    b.step(200)
    ra, rb = a.controllers[0], b.controllers[0]
    assert ra.log == rb.log and len(ra.log) > 20
    assert np.array_equal(ra.belief, rb.belief) and np.array_equal(ra.grid.belief, rb.grid.belief)


def test_a_restored_controller_goes_on_exactly_as_the_one_it_was_taken_from():
    from swarm.engines.arena import ArenaEngine
    from swarm.experiments.tapus2006.fingerprint import tour_scenario
    from world_server.arena.scenario import controller_params

    s = tour_scenario("office", "mapping", "low", 0)
    a = ArenaEngine(s)
    a.step(400)
    state = json.loads(json.dumps(a.controllers[0].snapshot()))  # plain data: it can be saved and sent
    b = ArenaEngine(s)
    b.world.restore(a.world.snapshot())
    c = b.controllers[0]
    c.reset(s.seed, 0, controller_params(s, 0))
    c.restore(state)
    a.step(300)
    b.step(300)
    ra, rb = a.controllers[0], b.controllers[0]
    assert ra.log == rb.log
    assert [to_string(n.mean.codes) for n in ra.map.nodes] == [to_string(n.mean.codes) for n in rb.map.nodes]
    assert np.array_equal(ra.map.belief, rb.map.belief)


def test_a_saved_map_holds_no_belief_and_localization_starts_uniform():
    """What the mapping robot believed at the end of its tour is not in the map it saves, and a robot
    localizing on a map starts from a uniform belief over its nodes whatever the map it is given holds: its
    first fix is the matching alone."""
    from swarm.engines.arena import ArenaEngine
    from swarm.experiments.tapus2006.fingerprint import tour_scenario
    from world_server.arena.scenario import controller_params

    saved = mapping_tour()[1]["map"]
    assert saved["belief"] == [] and len(saved["nodes"]) >= 10
    s = tour_scenario("office", "localize", "low", 1000)
    params = controller_params(s, 0)
    params["fingerprint"] = {**params.get("fingerprint", {}), "mode": "localize"}
    held = dict(saved, belief=np.eye(len(saved["nodes"]))[3].tolist(), current=3)  # a map that does hold one
    first = []
    for given in (saved, held):
        engine = ArenaEngine(s)
        c = engine.controllers[0]
        c.reset(s.seed, 0, {**params, "topomap": given})
        assert len(c.map.belief) == 0
        while not c.log:
            engine.step(1)
        first.append(np.asarray(c.map.belief, np.float64).copy())
    assert np.array_equal(first[0], first[1]) and first[1][3] < 0.5  # nothing of the held belief is left


def test_localize_mode_needs_a_map_and_says_so():
    from swarm.core.errors import RunError
    from swarm.engines.arena import ArenaEngine
    from swarm.experiments.tapus2006.fingerprint import tour_scenario

    with pytest.raises(RunError, match=r"'fingerprint' of robot 0 cannot start: ValueError: .* needs a map"):
        ArenaEngine(tour_scenario("office", "mapping", "low", 0, {"mode": "localize"}))


def test_a_malformed_map_is_refused_in_one_line():
    from agents.controllers.fingerprint.signatures import FingerprintSignatures, map_from_data

    with pytest.raises(ValueError, match="malformed"):
        map_from_data({"nodes": [{"mean": "x"}], "links": []}, FingerprintSignatures(Matcher()), MapParams())


def test_a_bad_fingerprint_table_names_the_field(tmp_path):
    from swarm.scenario import BUNDLED_DIR

    path = tmp_path / "office.toml"

    path.write_text((BUNDLED_DIR / "office.toml").read_text() + "\n[fingerprint]\nspacing = 0.1\ntheta = 3\n")
    r = run_cli("run", str(path), "--controller", "fingerprint", "--max-ticks", "5")
    assert r.returncode == 2
    assert "0 < theta < 1" in r.stderr and "Traceback" not in r.stderr
    path.write_text((BUNDLED_DIR / "office.toml").read_text() + '\n[fingerprint]\nfilter = "kalman"\n')
    r = run_cli("run", str(path), "--controller", "fingerprint", "--max-ticks", "5")
    assert r.returncode == 2
    assert "[fingerprint].filter: 'kalman'; expected one of grid, links" in r.stderr and "Traceback" not in r.stderr
    with pytest.raises(ScenarioError):
        load_scenario(str(tmp_path / "missing.toml"))


def test_swarm_run_office_with_the_fingerprint_controller_prints_its_map():
    r = run_cli("run", "office", "--controller", "fingerprint", "--max-ticks", "300")
    assert r.returncode in (0, 1), r.stderr
    assert "map:" in r.stdout and "fingerprints" in r.stdout and "nodes" in r.stdout


def test_the_recording_holds_the_map_as_graph_nodes_and_edges(tmp_path):
    from swarm.engines.arena import ArenaEngine
    from swarm.experiments.tapus2006.fingerprint import tour_scenario
    from swarm.recording.arena import ArenaRecorder

    s = tour_scenario("office", "mapping", "low", 0)
    engine = ArenaEngine(s)
    path = tmp_path / "fp.rrd"
    rec = ArenaRecorder(
        path, engine.world, engine.goals, {"run_id": "fp", "runtime": "in-process"}, controllers=engine.controllers
    )
    engine.step(600, rec)
    rec.close()
    from rerun.chunk import RrdReader

    entities = {c.entity_path.lstrip("/") for c in RrdReader(path).stream()}
    assert {"map/0", "map/0/belief", "map/0/fingerprint", "world/map/0/nodes", "world/map/0/links"} <= entities


def test_the_matching_probability_is_calibrated_as_the_defaults_say():
    """`swarm experiment fingerprint-calibrate` fits the defaults of AlignParams."""
    from swarm.experiments.tapus2006.fingerprint import calibration_pairs, fit_logistic

    d, same = calibration_pairs("office", "low", 0)
    centre, width = fit_logistic(d, same)
    p = AlignParams()
    assert centre == pytest.approx(p.centre, abs=0.01) and width == pytest.approx(p.width, abs=0.01)
    assert np.median(d[same]) < p.centre < np.median(d[~same])


# ---------------------------------------------------------- mapping together


def shared_pair():
    from agents.controllers.navigation.mapshare import SharedMap

    def ident(x):
        return x

    return [SharedMap(TopoMap(Labels(), MapParams(theta=0.3)), k, ident, ident) for k in (0, 1)]


def walk(m, labels: str, start: float = 0.0) -> None:
    pos = start
    for label in labels:
        for _ in range(3):
            m.observe(label, np.array([pos, 0.0]), np.array([0.5, 0.0]))
            pos += 0.5
        pos += 0.5


def test_robots_merge_each_others_places_one_node_per_place():
    a, b = shared_pair()
    walk(a.map, "ax")  # robot 0 maps a, x
    walk(b.map, "xby", start=10.0)  # robot 1 maps x (the same place), b, y
    b.receive(1, a.publish())  # its own publication is ignored
    a.receive(1, json.loads(json.dumps(b.publish())))  # plain data, as over the wire
    assert [n.mean for n in a.map.nodes] == list("axby")  # robot 1's x is robot 0's x: merged, not added
    assert a.merged == 1 and a.added == 2
    x, b_, y = a.local[(1, 0)], a.local[(1, 1)], a.local[(1, 2)]
    assert x == 1 and {(x, b_), (b_, y)} <= set(a.map.links)  # robot 1's links came over through the alias
    assert a.publish()["nodes"] == []  # nothing of its own changed: it sends no one else's nodes
    a.map.observe("b", np.array([30.0, 0.0]), np.array([0.5, 0.0]))  # robot 0 now at b (a loop into robot 1's node)
    a.adopt(a.map.current)
    assert a.map.current == b_ and b_ in a.adopted


def test_a_malformed_map_from_another_robot_is_refused_and_merges_nothing():
    a, b = shared_pair()
    walk(b.map, "xb")
    good = b.publish()
    for bad in ({"nodes": "x"}, {"nodes": [[0, "a", [1.0], 1, 1]], "links": []},
                {"nodes": [[0, "a", [0.0, float("nan")], 1, 1]], "links": []},
                {**good, "links": [[1, 0, 1, 1, 0.5, "x", 1]]}):  # fmt: skip
        with pytest.raises(ValueError, match="a map from agent 1: malformed"):
            a.receive(1, bad)
    assert a.map.nodes == []
    from agents.controllers.arena import deliver
    from swarm.core.wire import pack
    from tests.arena_helpers import MapSharer

    robots = [MapSharer(a), MapSharer(b)]
    refused = deliver(
        robots, [0, 1], [(1, "map", b"\xc1garbage"), (1, "map", pack({"nodes": 1})), (1, "map", pack(good))]
    )
    assert refused == 2 and len(a.map.nodes) == 2


def test_shared_items_on_the_wire_are_checked():
    from swarm.core.wire import Rejected
    from world_server.arena.face import wire as arena_proto

    msg = arena_proto.parse_acts(arena_proto.actions(3, [0], np.zeros((1, 2)), [(0, "map", b"x")]))
    assert msg.shared == [(0, "map", b"x")]
    for bad in ("x", [[0, "map"]], [[True, "map", b""]], [[0, 1, b""]], [[0, "map", "text"]]):
        assert isinstance(arena_proto.parse_shared(bad), Rejected)


@pytest.mark.parametrize(("processes", "per_process"), [(2, 1), (1, 2)])
def test_mapping_together_lockstep_equals_in_process(processes, per_process, tmp_path):
    from swarm.core import wire
    from swarm.core.bus import open_client
    from swarm.engines.arena import ArenaEngine
    from swarm.experiments.tapus2006.team import team_scenario
    from tests.distributed import run_world

    scenario = team_scenario(2, "low", 0).with_overrides(max_ticks=400)
    engine = ArenaEngine(scenario)
    expected = engine.run()
    assert engine.controllers[0].shared.added > 0  # robot 0 has robot 1's places by then
    held: dict[int, list] = {}

    def read_key_space(endpoint, keys):  # any client can get what the robots wrote
        import time

        session = open_client(endpoint)
        try:
            for _ in range(300):
                for reply in session.get(f"{keys.prefix}/map/**", timeout=2.0):
                    if reply.ok is not None:
                        m = wire.unpack(reply.ok.payload.to_bytes(), 1 << 26)
                        held[m["agent"]] = m["updates"]
                if len(held) == 2:
                    return
                time.sleep(0.1)
        finally:
            session.close()

    run_id = f"fp-team-{processes}"
    rrd = tmp_path / "team.rrd"
    summary, world = run_world(scenario, run_id, [("fingerprint", processes, per_process)], read_key_space,
                               deadline=20.0, record=str(rrd))  # fmt: skip
    np.testing.assert_array_equal(world.pose, engine.world.pose)
    assert [r["shared"] for r in summary["robots"]] == [r["shared"] for r in expected["robots"]]
    assert summary["rejected_messages"] == 0
    assert set(held) == {0, 1} and all(held.values())
    from rerun.chunk import RrdReader

    entities = {c.entity_path.lstrip("/") for c in RrdReader(rrd).stream()}  # the world drew both maps
    assert {"map/0", "map/1", "world/map/0/nodes", "world/map/1/links"} <= entities


def test_a_young_node_that_turns_out_to_be_a_known_place_is_folded_into_it():
    """Coming back to a through a view that matched nothing ('d', a door), the
    next observations match a: the young node d folds into a (a loop closed late)."""
    m = corridor_map()
    places = m.size
    m.observe("d", np.array([20.0, 0.0]), np.array([0.5, 0.0]))  # a new node, young
    young = m.current
    assert m.size == places + 1
    m.observe("a", np.array([20.5, 0.0]), np.array([0.5, 0.0]))
    assert m.folded == {young: 0} and m.current == 0 and m.size == places
    assert m.resolve(young) == 0 and all(young not in link for link in m.links)
    assert (0, 3) in m.links  # y, where the robot came from, is now linked to a
    assert np.isclose(m.likelihood[young], 0.0) or m._likelihoods("d")[young] == 0.0
