"""The bg animat (Girard et al. 2005): the world's metabolism, the animat's
senses, motivations and saliences, its map, and the controller in both
runtimes.  The GPR loops are in test_bg_gpr.py."""

import csv
import dataclasses
import json
import math
import re

import numpy as np
import pytest

from agents.controllers.bg.controller import BgController
from agents.controllers.bg.params import NavParams
from agents.controllers.bg.places import ANGLES, DIRECTIONS, Navigator, _explore_channel
from agents.controllers.bg.saliences import Drives, plan_vector, saliences
from agents.controllers.bg.senses import Reflex, proximity, resource_pixels, sense, to_allocentric
from agents.controllers.navigation.dijkstra import shortest_routes
from swarm.core.errors import ScenarioError
from swarm.core.wire import Rejected
from swarm.engines.arena import ArenaEngine
from swarm.scenario import load_scenario
from tests.arena_helpers import arena, box, resumed_pair, rrd_rows
from world_server.arena.face import wire as proto
from world_server.arena.scenario import controller_params
from world_server.arena.world import ArenaWorld

FOOD = (
    "[metabolism]\n{extra}\n"
    '[[resource]]\nname = "food"\nkind = "ingesting"\ncentre = [0.6, 0.5]\n'
    '[[resource]]\nname = "rest"\nkind = "digesting"\ncentre = [2.4, 0.5]\n'
    '[[resource]]\nname = "danger"\nkind = "dangerous"\ncentre = [1.5, 1.5]\n'
    '[[group]]\ncount = 1\ncontroller = "bg"\nrobot = "animat"\nstart = [{x}, {y}, 0.0]\n'
)


def _world(x: float = 1.2, y: float = 0.5, extra: str = "", **kw) -> ArenaWorld:
    text = FOOD.format(extra=extra, x=x, y=y)
    return ArenaWorld(arena(text, w=3.0, h=2.0, robot="animat", **kw))


# ------------------------------------------------------------- metabolism


def test_a_full_energy_lasts_33_minutes_then_the_animat_dies_and_stops():
    w = _world(extra="energy = 0.01\n")
    dt = w.scenario.control_period
    ticks = math.ceil(0.01 * 1980 / dt)
    for _ in range(ticks - 1):
        w.apply(np.zeros((1, 3)))
    assert w.metabolism.alive[0] and w.metabolism.energy[0] == pytest.approx(0.01 - (ticks - 1) * dt / 1980)
    w.apply(np.zeros((1, 3)))
    assert not w.metabolism.alive[0] and w.finished[0] and w.done()
    pose = w.pose.copy()
    w.apply(np.array([[0.3, 0.3, 0.0]]))
    assert np.array_equal(w.pose, pose)  # a dead animat does not move


def test_a_metabolism_step_gives_the_numpy_formulas_numbers_to_the_bit():
    from world_server.arena.face.sensors.zones import ZONE_KINDS
    from world_server.arena.metabolism import Metabolism, MetabolismParams

    rng = np.random.default_rng(9)
    n, p, dt = 64, MetabolismParams(lifetime=30.0, danger_rate=0.05), 0.25
    m = Metabolism(n, p, dt, [("food", "ingesting", (0.0, 0.0)), ("rest", "digesting", (1.0, 0.0))])
    m.energy, m.potential = rng.uniform(0, 1, n), rng.uniform(0, 1, n)
    energy, potential, alive = m.energy.copy(), m.potential.copy(), m.alive.copy()
    acts_done, idle, died_tick = m.acts.copy(), m.idle_acts.copy(), m.died_tick.copy()
    for tick in range(60):
        acts, bits, moving = rng.integers(0, 3, n), rng.integers(0, 64, n), rng.random(n) < 0.9
        m.step(acts, bits, moving, np.zeros((n, 2)), tick)
        live = alive & moving  # the numpy formulas the kernel replaced
        zone = {k: (bits & (1 << ZONE_KINDS.index(k))) != 0 for k in ("ingesting", "digesting", "dangerous")}
        for code, kind in ((1, "digesting"), (2, "ingesting")):
            works = live & (acts == code) & zone[kind]
            idle += live & (acts == code) & ~works
            acts_done[:, code] += works
            if code == 2:
                potential = np.where(works, np.minimum(1.0, potential + p.ingest_rate * dt), potential)
            else:
                gain = np.minimum.reduce([np.full(n, p.digest_rate * dt), potential, 1.0 - energy])
                gain = np.where(works, np.maximum(gain, 0.0), 0.0)
                energy, potential = energy + gain, potential - gain
        loss = dt / p.lifetime + np.where(zone["dangerous"], p.danger_rate * dt, 0.0)
        energy = np.where(alive, np.maximum(energy - loss, 0.0), energy)
        died = alive & (energy <= 0.0)
        died_tick[died] = tick
        alive &= ~died
        assert np.array_equal(m.energy, energy) and np.array_equal(m.potential, potential)
        assert np.array_equal(m.alive, alive) and np.array_equal(m.died_tick, died_tick)
        assert np.array_equal(m.acts, acts_done) and np.array_equal(m.idle_acts, idle)
    assert 0 < alive.sum() < n  # some died on the way, some lived: every branch ran


def test_reloading_works_only_in_a_zone_of_its_kind():
    w = _world(x=1.2, extra="potential = 0.5\nenergy = 0.5\n")  # 0.6 m from the food's centre: within reach
    before = w.metabolism.levels(np.array([0]))[0].copy()
    w.apply(np.array([[0.0, 0.0, 2.0]]))  # ReloadEp at the food
    ep = w.metabolism.potential[0]
    assert ep == pytest.approx(before[1] + 0.1 * w.scenario.control_period)
    assert w.metabolism.ingest_tick[0] == 0
    assert w.metabolism.summary(0, w.scenario.control_period, w.tick)["ingested"] == "food"
    w.apply(np.array([[0.0, 0.0, 1.0]]))  # ReloadE away from the digesting zone: nothing, counted
    assert w.metabolism.idle_acts[0] == 1 and w.metabolism.potential[0] == pytest.approx(ep)


def test_digesting_turns_potential_energy_into_energy():
    w = _world(x=2.4 - 0.6, extra="potential = 0.5\nenergy = 0.5\n")
    dt = w.scenario.control_period
    w.apply(np.array([[0.0, 0.0, 1.0]]))
    e, ep = w.metabolism.levels(np.array([0]))[0]
    assert ep == pytest.approx(0.5 - 0.1 * dt) and e == pytest.approx(0.5 + 0.1 * dt - dt / 1980)


def test_a_dangerous_area_drains_energy():
    calm, danger = _world(x=1.2, y=0.5), _world(x=1.5, y=1.1)
    for w in (calm, danger):
        w.apply(np.zeros((1, 3)))
    dt = calm.scenario.control_period
    assert calm.metabolism.energy[0] - danger.metabolism.energy[0] == pytest.approx(0.01 * dt)


def test_the_animat_senses_its_energy_and_the_state_resumes():
    w = _world(extra="energy = 0.7\npotential = 0.3\n")
    assert np.allclose(w.perceive()[0]["metabolism"], [0.7, 0.3])
    w.apply(np.array([[0.0, 0.0, 2.0]]))
    saved = w.snapshot()
    other = _world(extra="energy = 0.7\npotential = 0.3\n")
    other.restore(saved)
    assert np.array_equal(other.metabolism.energy, w.metabolism.energy)
    assert other.metabolism.ingest_tick[0] == w.metabolism.ingest_tick[0]


@pytest.mark.parametrize("table, field", [
    ("energy = 2.0", "metabolism.energy"), ("lifetime = 0", "metabolism.lifetime"),
    ('stop_at = "never"', "metabolism.stop_at"), ("rate = 1", "metabolism.rate"),
])  # fmt: skip
def test_a_bad_metabolism_table_is_one_clear_line(table, field):
    with pytest.raises(ScenarioError) as e:
        arena(FOOD.format(extra=table, x=1.2, y=0.5), w=3.0, h=2.0, robot="animat")
    assert field in str(e.value) and "\n" not in str(e.value)


def test_acts_cross_the_wire_only_when_there_are_some():
    plain = proto.parse_acts(proto.actions(3, [0, 1], np.array([[0.1, 0.1, 0.0], [0.2, 0.2, 0.0]])))
    assert plain.wheels.shape == (2, 2)
    acting = proto.parse_acts(proto.actions(3, [0, 1], np.array([[0.1, 0.1, 2.0], [0.2, 0.2, 0.0]])))
    assert acting.wheels.shape == (2, 3) and acting.wheels[0, 2] == 2.0
    from swarm.core.wire import pack, unpack

    m = unpack(proto.actions(3, [0, 1], np.array([[0.1, 0.1, 2.0], [0.2, 0.2, 0.0]])), 1 << 20)
    m["acts"] = b"\x00" * 3
    assert isinstance(proto.parse_acts(pack(m)), Rejected)


# ------------------------------------------------------------------ senses


def test_prox_counts_the_run_through_each_direction_within_seven_pixels():
    pixels = np.zeros((1, 36), bool)
    pixels[0, [5, 6, 7]] = True
    pixels[0, 20:36] = True
    counts = np.rint(proximity(pixels) * 7).astype(int)[0]
    assert list(counts[4:9]) == [0, 3, 3, 3, 0]  # a small resource: 3/7 where it is, nothing beside it
    assert counts[27] == 7 and counts[20] == 4 and counts[35] == 4  # a large one fills windows inside it


def test_prox_is_the_run_through_the_centre_cut_to_the_window_on_random_views():
    rng = np.random.default_rng(3)
    for _ in range(50):
        pixels = rng.random((3, 36)) < rng.uniform(0.1, 0.9)
        expected = np.zeros((3, 36))
        for r, d in np.argwhere(pixels):  # walk out from the centre pixel, at most 3 each way
            after = next((k for k in range(1, 4) if not pixels[r, (d + k) % 36]), 4) - 1
            before = next((k for k in range(1, 4) if not pixels[r, (d - k) % 36]), 4) - 1
            expected[r, d] = (1 + after + before) / 7
        assert np.array_equal(proximity(pixels), expected)


def test_allocentric_resampling_gives_numpys_numbers_to_the_bit():
    rng = np.random.default_rng(4)
    for n in (8, 36):
        for _ in range(40):
            readings, heading = rng.uniform(0, 5, n), float(rng.uniform(-10, 10))
            pos = (np.arange(n) - heading * n / (2 * math.pi)) % n  # the formula as numpy arrays
            lo = np.floor(pos).astype(np.int64)
            f = pos - lo
            expected = readings[lo] * (1 - f) + readings[(lo + 1) % n] * f
            assert np.array_equal(to_allocentric(readings, heading), expected)
    assert np.array_equal(to_allocentric(np.arange(8.0), 0.0), np.arange(8.0))  # heading east: unchanged


def test_the_exploration_channel_is_numpys_interp_clip_and_argmax_to_the_bit():
    rng = np.random.default_rng(5)
    for _ in range(200):
        sonar, novel = rng.uniform(0, 3, 8), rng.uniform(0, 1, 36)
        wander = rng.uniform(0, 0.5, 36) if rng.random() < 0.8 else np.zeros(36)
        open_range = float(rng.choice([0.5, 1.0, 2.0]))
        room = np.interp(ANGLES, np.arange(9) * (2 * math.pi / 8), np.append(sonar, sonar[0]))
        score = np.clip(room / open_range - 0.5, 0.0, 1.0) * (0.5 * novel + wander)
        expected = int(np.argmax(score)) if score.max() > 0 else -1
        assert _explore_channel(sonar, open_range, novel, wander) == expected
    assert _explore_channel(np.full(8, 0.1), 1.0, np.ones(36), np.zeros(36)) == -1  # no room anywhere


def test_resource_pixels_are_turned_allocentric_by_the_compass():
    grey = np.full(36, 180, np.uint8)
    grey[0] = 127  # straight ahead: an ingesting zone
    pixels = resource_pixels(grey, math.radians(90))
    assert pixels[1, 9] and pixels[1].sum() == 1  # heading north: the Ep pixel is the 90-degree direction


def test_the_reflex_turns_to_the_roomier_side_and_holds_its_choice():
    r = Reflex(too_close=0.45, hold=1.0)
    sonar = np.array([0.3, 2.0, 2.0, 2.0, 2.0, 0.5, 0.5, 0.5])  # wall ahead; room on the left (sonars 1-3)
    assert r(sonar, 0.25) == (0.0, 1.0)
    assert r(np.array([0.3, 0.5, 0.5, 0.5, 2.0, 2.0, 2.0, 2.0]), 0.25)[1] == 1.0  # keeps turning left
    assert r(np.full(8, 3.0), 0.25) == (1.0, 0.0)  # clear: straight on for `hold`
    for _ in range(4):
        r(np.full(8, 3.0), 0.25)
    assert r(np.full(8, 3.0), 0.25) is None  # then the BG has the body again


# ------------------------------------------------------ motivations, saliences


def _drives(e=1.0, ep=1.0, **kw) -> Drives:
    base = {"fear": 0.2, "disorientation": 0.0, "prox": np.zeros((3, 36)), "usable": np.zeros(3, bool),
            "plan": np.zeros((3, 36)), "bka": np.zeros(36), "expl": np.zeros(36)}  # fmt: skip
    base.update(kw)
    return Drives(e, ep, **base)


def test_motivations_follow_equation_2():
    d = _drives(e=0.4, ep=0.3)
    assert d.m_e == pytest.approx(0.6 * math.sqrt(1 - 0.7**2)) and d.m_ep == pytest.approx(0.7)
    assert _drives(e=0.4, ep=0.0).m_e == 0.0  # no Ep to digest: no drive to the digesting zone


def test_plan_combines_needs_and_fear_subtracts_danger():
    p = np.zeros((3, 36))
    p[1, 5], p[2, 5], p[0, 7] = 0.8, 0.5, 1.0
    d = _drives(e=0.0, ep=0.5, plan=p)
    expected = 1 - (1 - d.m_e * 0.5) * (1 - d.m_ep * 0.8)
    assert plan_vector(d, False)[5] == pytest.approx(expected)
    assert plan_vector(d, True)[7] == 0.0 and plan_vector(d, False)[7] == 0.0  # clipped at 0 for the root
    p[1, 7] = 0.8
    assert plan_vector(_drives(e=0.0, ep=0.5, plan=p), True)[7] < plan_vector(_drives(e=0.0, ep=0.5, plan=p), False)[7]


def _numpy_saliences(d: Drives, kind: str, w_plan: float, w_taxon: float) -> tuple[np.ndarray, np.ndarray]:
    """Eqs. 1 and 15-20 as numpy array expressions: what the compiled kernel must give to the bit."""
    m_e, m_ep, m_bka = d.m_e, d.m_ep, d.disorientation
    mprox, a = d.prox.max(axis=1), d.usable.astype(np.float64)
    if kind == "tmaze":
        dorsal = np.array([0.9 * a[2] * m_e + 0.1 * mprox[2] * m_e, 0.9 * a[1] * m_ep + 0.1 * mprox[1] * m_ep])
    else:
        dorsal = np.array([1.2 * a[2] * m_e + 0.6 * mprox[2] * m_e, a[1] * m_ep + 0.2 * mprox[1] * m_ep])
    planned = 1.0 - (1.0 - m_e * d.plan[2]) * (1.0 - m_ep * d.plan[1])
    plan = np.sqrt(np.maximum(planned - d.fear * d.plan[0] if kind == "fear" else planned, 0.0))
    sq = np.sqrt(d.prox)
    if kind == "fear":
        return dorsal, (0.45 * plan + 0.35 * sq[2] * m_e + 0.35 * sq[1] * m_ep + 0.19 * (1.0 - d.prox[0]) * d.fear
                        + 0.4 * d.bka * m_bka
                        + d.expl * (0.05 + 0.05 * (1 - mprox[1]) * m_ep + 0.05 * (1 - mprox[2]) * m_e))  # fmt: skip
    term = 0.55 * plan * (1.0 - mprox[2]) * (1.0 - mprox[1]) if kind == "tmaze" else w_plan * plan
    return dorsal, (term + 0.55 * sq[2] * m_e + w_taxon * sq[1] * m_ep + 0.4 * d.bka * m_bka
                    + d.expl * (0.25 + 0.05 * (1 - mprox[1]) * m_ep + 0.05 * (1 - mprox[2]) * m_e))  # fmt: skip


def test_the_compiled_saliences_are_the_equations_numbers_to_the_bit():
    rng = np.random.default_rng(6)
    for k in range(60):
        prox = np.where(rng.random((3, 36)) < 0.3, rng.integers(1, 8, (3, 36)) / 7, 0.0)
        d = _drives(e=float(rng.random()), ep=float(rng.random()), fear=float(rng.random()),
                    disorientation=float(rng.random()), prox=prox, usable=rng.random(3) < 0.5,
                    plan=rng.random((3, 36)) * (rng.random((3, 36)) < 0.5), bka=rng.random(36),
                    expl=rng.random(36))  # fmt: skip
        kind = ("survival", "fear", "tmaze")[k % 3]
        dorsal, ventral, planned = saliences(d, kind, 0.65, 0.55)
        want_dorsal, want_ventral = _numpy_saliences(d, kind, 0.65, 0.55)
        assert np.array_equal(dorsal, want_dorsal) and np.array_equal(ventral, want_ventral)
        assert np.array_equal(planned, plan_vector(d, kind == "fear"))


def test_usable_food_drives_the_dorsal_loop_and_lower_weights_in_the_tmaze():
    prox = np.zeros((3, 36))
    prox[1, 3:10] = 1.0
    d = _drives(e=1.0, ep=0.2, prox=prox, usable=np.array([False, True, False]))
    dorsal, _, _ = saliences(d, "survival", 0.65, 0.55)
    assert dorsal[1] == pytest.approx(0.8 + 0.2 * 0.8) and dorsal[0] == 0.0  # eq. 16
    assert saliences(d, "tmaze", 0.65, 0.55)[0][1] == pytest.approx(0.9 * 0.8 + 0.1 * 0.8)  # eq. 20


# -------------------------------------------------------------- navigation


def _nav() -> Navigator:
    return Navigator(NavParams(), seed=0, agent=0, resources=("DA", "Ep", "E"))


def _place(k: int) -> tuple[np.ndarray, np.ndarray]:
    grey = np.full(36, 40 + 60 * k, np.uint8)
    return grey, np.full(8, 1.0 + 1.0 * k)


def test_routes_are_scipys_dijkstra_to_the_bit():
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import dijkstra

    rng = np.random.default_rng(7)
    for _ in range(30):
        n = int(rng.integers(2, 60))
        pairs = {(int(a), int(b)) for a, b in rng.integers(0, n, (2 * n, 2)) if a != b}
        heads, tails = np.array([p[0] for p in pairs], np.int64), np.array([p[1] for p in pairs], np.int64)
        lengths = rng.uniform(1e-3, 2.0, len(pairs))
        lengths[rng.random(len(pairs)) < 0.1] = 0.0  # zero-length edges are edges (the map's sure sources)
        source = int(rng.integers(0, n))
        dist, pred = shortest_routes(n, source, heads, tails, lengths)
        want_dist, want_pred = dijkstra(csr_matrix((lengths, (heads, tails)), shape=(n, n)), directed=True,
                                        indices=source, return_predecessors=True)  # fmt: skip
        assert np.array_equal(dist, want_dist)
        # predecessors agree wherever the shortest route is unique (random lengths; zero edges can tie)
        unique = [v for v in range(n) if not any(lengths[e] == 0.0 for e in range(len(heads)) if tails[e] == v)]
        assert np.array_equal(pred[unique], want_pred[unique])


def test_the_map_learns_where_food_is_forgets_it_when_gone_and_plans_to_it():
    nav = _nav()
    for k in range(4):  # a straight corridor eastwards, a different place every 0.3 m
        nav.move(0.3 if k else 0.0, 0.0)
        nav.observe(*_place(k), 0.0)
    assert nav.map.size == 4 and nav.map.current == 3
    for _ in range(6):  # it stays there a while (a node no longer young)
        nav.observe(*_place(3), 0.0)
    for _ in range(200):
        nav.learn({"Ep": True}, {"Ep": True}, 0.25)  # food usable at the east end
    assert nav.assoc["Ep"][3] > 0.9
    nav.move(-0.3, 0.0)  # back west, to the first node (heading 0, moving backwards)
    for k in (2, 1, 0):
        nav.move(-0.3 if k < 2 else 0.0, 0.0)
        nav.observe(*_place(k), 0.0)
    towards = nav.plan("Ep")
    assert abs(ANGLES[int(np.argmax(towards))]) < 0.3 and towards.max() > 0.3  # east, along the corridor
    nav.map.belief = np.eye(4)[3]
    for _ in range(600):  # 150 s at the east end with the food in sight but out of reach: kept
        nav.learn({"Ep": False}, {"Ep": True}, 0.25)
    assert nav.assoc["Ep"][3] > 0.9
    for _ in range(600):  # 150 s there and no food in sight: forgotten
        nav.learn({"Ep": False}, {"Ep": False}, 0.25)
    assert nav.assoc["Ep"][3] < 0.1


def _corridor(nav: Navigator, legs: list[tuple[float, int]]) -> None:
    """Drive `legs` (heading, steps of 0.3 m), observing a new look of its own at each step."""
    k = 0
    for heading, steps in legs:
        for _ in range(steps):
            nav.move(0.3 if k else 0.0, heading)
            nav.observe(np.full(36, 20 + 25 * k, np.uint8), np.full(8, 0.5 + 2.0 * k), 0.0)
            k += 1


@pytest.mark.parametrize("pursuit, heading", [(0.5, 0.0), (0.0, math.radians(45))])
def test_with_pursuit_the_plan_points_at_the_next_place_on_the_way_not_across_a_corner(pursuit, heading):
    """An L-shaped way: four places eastwards, then three northwards, food at the end.  From the second
    place, with `pursuit` the plan points east at the corner's place (0.6 m on); the sum of the route's
    first metre (the default) points north-east, through the corner."""
    nav = Navigator(NavParams(pursuit=pursuit), seed=0, agent=0, resources=("DA", "Ep", "E"))
    _corridor(nav, [(0.0, 4), (math.pi / 2, 3)])
    nav.map.belief = np.eye(nav.map.size)[6]
    for _ in range(40):
        nav.learn({"Ep": True}, {"Ep": True}, 0.25)
    nav.map.current, nav.at = 1, nav.map.nodes[1].position.copy()  # seen back at the second place
    towards = nav.plan("Ep")
    assert towards.max() > 0.5 and abs(ANGLES[int(np.argmax(towards))] - heading) <= math.radians(10)


@pytest.mark.parametrize("ways", ["best", "places"])
def test_with_places_each_place_holding_a_resource_pulls_its_own_way(ways):
    """A corridor eastwards with food at both ends, the animat 0.6 m from the west end and 1.5 m from the east
    one: the best route alone points west; with `ways = "places"` the east end pulls too, each as strongly
    as exp(-route / reach) (experiment 3.1: the far Ep2 must compete with the near Ep1, docs/bg.md)."""
    nav = Navigator(NavParams(ways=ways), seed=0, agent=0, resources=("DA", "Ep", "E"))
    _corridor(nav, [(0.0, 8)])  # places at x = 0, 0.3, ..., 2.1
    for end in (7, 0):
        nav.map.belief = np.eye(nav.map.size)[end]
        for _ in range(40):
            nav.learn({"Ep": True}, {"Ep": True}, 0.25)
    assert nav._places(np.array([0, 7]), nav.assoc["Ep"])[0].tolist() == [0]  # 2.1 m apart: two places
    nav.map.current, nav.at = 2, nav.map.nodes[2].position.copy()
    towards = nav.plan("Ep")
    west, east = towards[DIRECTIONS // 2], towards[0]
    assert west == pytest.approx(math.exp(-0.6 / nav.p.reach), rel=1e-3)
    assert east == (pytest.approx(math.exp(-1.5 / nav.p.reach), rel=1e-3) if ways == "places" else
                    pytest.approx(west * math.exp(-8.0), rel=1e-3))  # the west bump's far tail  # fmt: skip


@pytest.mark.parametrize("known", [1.0, 0.0])
def test_expl_is_as_high_as_its_direction_is_unmapped_when_known_explore_is_0(known):
    """Expl points "to explore unmapped areas": with known_explore 0 its bump is as high as the novelty of the
    direction it picks (none where the map knows the way); with 1 (the default) it is 1 wherever it points."""
    nav = Navigator(NavParams(known_explore=known), seed=0, agent=0, resources=("DA", "Ep", "E"))
    assert nav.explore(np.full(8, 5.0), 0.0, 0.0, True).max() == pytest.approx(1.0)  # no map: all novel
    _corridor(nav, [(0.0, 5), (math.pi / 2, 4)])  # an L of places: the way back is mapped, the rest is not
    heights = []
    for period in range(40):
        out = nav.explore(np.full(8, 5.0), 0.0, 20.0 * period, True)
        best = int(np.argmax(out))
        heights.append(out[best])
        assert out[best] == pytest.approx(1.0 if known == 1.0 else nav._novel[best])
    assert (min(heights) < 0.9) == (known == 0.0)  # some draws point where the map has nodes


@pytest.mark.parametrize("radius, reached", [(None, [False, False, True, True, True, True]), (2.0, [True] * 6)])
def test_a_loop_closes_only_onto_a_place_within_the_closure_radius(radius, reached):
    """bg-exp1's two rooms mirror each other across the middle wall: with loops closing onto nodes up to 2 m
    away by odometry they close through the wall.  At 1 m (the default) a node 1.25 m away is out of reach."""
    params = NavParams() if radius is None else NavParams(closure_radius=radius)
    nav = Navigator(params, seed=0, agent=0, resources=("DA", "Ep", "E"))
    _corridor(nav, [(math.pi / 2, 6)])  # places at y = 0, 0.3, ..., 1.5 (x = 0)
    assert nav.map.size == 6
    assert nav.map._within_reach(np.array([0.0, 1.55])).tolist() == reached  # 1.55, 1.25, 0.95 ... m away


@pytest.mark.parametrize("anchor", [0.2, 0.0])
def test_with_anchor_recognizing_a_place_pulls_drifted_odometry_part_of_the_way_to_it(anchor):
    nav = Navigator(NavParams(anchor=anchor), seed=0, agent=0, resources=("DA", "Ep", "E"))
    _corridor(nav, [(0.0, 3)])  # places at x = 0, 0.3, 0.6
    nav.xy = np.array([0.6, 0.5])  # odometry has drifted 0.5 m north of the last place
    nav.since = np.array([0.0, 0.3])
    node = nav.observe(np.full(36, 20 + 25 * 2, np.uint8), np.full(8, 0.5 + 2.0 * 2), 0.0)  # the last place again
    position = nav.map.nodes[node].position
    assert node == 2 and position[1] > 0.0  # the node's mean took the drifted observation in ...
    assert nav.xy[1] == pytest.approx(0.5 + anchor * (position[1] - 0.5))  # ... and odometry moved to it (or not)
    assert np.array_equal(nav.at, nav.xy)


def test_a_saved_map_loads_back_exactly_and_a_bad_one_is_one_line():
    nav = _nav()
    for k in range(3):
        nav.move(0.3, 0.0)
        nav.observe(*_place(k), 0.0)
    data = json.loads(json.dumps(nav.to_data()))
    other = _nav()
    other.from_data(data)
    assert other.to_data() == nav.to_data()
    data["map"]["nodes"][0]["mean"] = [1.0, 2.0]
    with pytest.raises(ValueError, match="a bg map: malformed") as e:
        _nav().from_data(data)
    assert "\n" not in str(e.value)


# -------------------------------------------------------------- controller


def test_the_animat_reloads_at_food_it_sees_and_then_goes_on():
    """Hungry for Ep beside an ingesting zone: it selects ReloadEp, the world raises Ep, and once sated it moves."""
    s = arena(FOOD.format(extra="energy = 1.0\npotential = 0.3\n", x=1.2, y=0.5), w=3.0, h=2.0, robot="animat",
              noise="low", max_ticks=600)  # fmt: skip
    s = s.with_overrides(start=(1.2, 0.5, math.pi))  # facing the food, 0.6 m away
    engine = ArenaEngine(s)
    engine.step(400)
    r = engine.summary()["robots"][0]
    assert r["reloads"]["ReloadEp"] > 10 and r["potential"] > 0.6 and r["ingested"] == "food"
    assert r["distance"] > 0.1 and engine.summary()["rejected_actions"] == 0


@pytest.mark.parametrize("dorsal_threshold, reloads", [(0.5, True), (None, False)])
def test_beside_food_a_moderate_need_tops_up_only_below_the_dorsal_threshold(dorsal_threshold, reloads):
    """Ep 0.65 beside an ingesting zone its camera sees fill the window (A(Ep)): ReloadEp's channel is released
    to about 0.9, just under the 0.9 an act needs by default, so the animat does not top up; with the dorsal
    threshold at 0.5 it does.  One threshold, wherever the animat is."""
    s = arena(FOOD.format(extra="energy = 1.0\npotential = 0.65\n", x=1.2, y=0.5), w=3.0, h=2.0, robot="animat",
              noise="low", max_ticks=600)  # fmt: skip
    params = dict(s.controller_params)
    if dorsal_threshold is not None:
        params["bg"] = {**params.get("bg", {}), "dorsal_threshold": dorsal_threshold}
    engine = ArenaEngine(dataclasses.replace(s.with_overrides(start=(1.2, 0.5, math.pi)), controller_params=params))
    engine.step(400)
    r = engine.summary()["robots"][0]
    assert (r["reloads"]["ReloadEp"] > 10 and r["potential"] > 0.8) == reloads, r["reloads"]


@pytest.mark.parametrize("cross", [0.4, 0.0])
def test_during_an_act_eq_10s_cross_term_is_what_keeps_the_ventral_loop_from_steering(cross):
    """Hungry for Ep beside food, with the wheels not held: while ReloadEp is selected the trans-subthalamic
    term (the declared 0.4) lifts the ventral outputs so that a direction is released in a minority of the
    act's ticks; without it (0), in every one.  The loops, not a rule, stop the animat (docs/bg.md)."""
    s = arena(FOOD.format(extra="energy = 1.0\npotential = 0.3\n", x=1.2, y=0.5), w=3.0, h=2.0, robot="animat",
              noise="low", max_ticks=600)  # fmt: skip
    params = dict(s.controller_params)
    params["bg"] = {**params.get("bg", {}), "gpr": {"cross": cross}}
    engine = ArenaEngine(dataclasses.replace(s.with_overrides(start=(1.2, 0.5, math.pi)), controller_params=params))
    animat, acts, steered = engine.controllers[0], 0, 0
    assert not animat.p.hold_wheels
    for _ in range(400):
        engine.step(1)
        if animat.last["act"] > 0:
            acts += 1
            steered += not math.isnan(animat.last["direction"])
    assert acts > 50, acts  # it ate
    assert (steered < acts / 3) if cross else (steered == acts), (acts, steered)


class _ReadLog(dict):
    """A perception that remembers which of its readings the controller asked for."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.read: set[str] = set()

    def __getitem__(self, key):
        self.read.add(key)
        return super().__getitem__(key)

    def get(self, key, default=None):
        self.read.add(key)
        return super().get(key, default)


# What the paper's animat senses (section 3.2): its camera, sonars, odometry and compass, and its own E and Ep.
PAPER_SENSORS = {"camera", "sonar", "odometry", "compass"}
PAPER_SENSES = {"camera_grey", "sonar", "odometry", "compass", "metabolism"}  # their readings


def test_the_animat_reads_only_the_senses_the_paper_gives_it_and_learns_resources_from_its_camera():
    """No world truth: every reading the controller takes is one of the paper's senses (the world's zone bits
    are offered and never read), and A(res), which starts an act and teaches the map where a resource is,
    is mProx(res) = 1 from the camera, as the paper defines it."""
    from agents.controllers.bg import CONTROLLERS

    assert set(CONTROLLERS.requires) <= PAPER_SENSORS
    s = load_scenario("bg-exp1").with_overrides(max_ticks=2400)
    engine = ArenaEngine(s)
    animat = engine.controllers[0]
    read: set[str] = set()
    offered: set[str] = set()
    step = animat.step

    def logged(perception):
        log = _ReadLog(perception)
        log["zones"] = np.int64(0b111)  # world truth on offer: were it read, every resource would be usable
        offered.update(log)
        out = step(log)
        read.update(log.read)
        return out

    animat.step = logged
    engine.step(2400)
    assert "zones" in offered and read <= PAPER_SENSES, read - PAPER_SENSES
    # a view that fills the 7-pixel window makes the resource usable; a narrower one does not
    grey = np.full(36, 180.0)
    grey[:7] = 255.0  # E across sectors 0-6: direction 3 sees it fill its window
    prox, _ = sense(grey, 0.0)
    assert prox[2].max() == 1.0 and prox[1].max() == 0.0
    grey[6] = 180.0
    assert sense(grey, 0.0)[0][2].max() < 1.0


def test_snapshot_and_restore_continue_bit_for_bit():
    a, b = resumed_pair(load_scenario("bg-exp1").with_overrides(max_ticks=400), 200)
    np.testing.assert_array_equal(a.world.pose, b.world.pose)
    assert a.controllers[0].snapshot() == b.controllers[0].snapshot()


def test_a_bad_bg_table_is_one_clear_line():
    text = box(FOOD.format(extra="", x=1.2, y=0.5) + '[bg]\nsaliences = "hunger"\n', w=3.0, h=2.0, robot="animat")
    from swarm.scenario import parse_arena_text

    with pytest.raises(ScenarioError) as e:
        parse_arena_text(text, "bad.toml")
    assert "saliences" in str(e.value) and "\n" not in str(e.value)
    c = BgController()
    params = controller_params(load_scenario("bg-exp1"), 0)
    params["bg"] = {"map": "/nonexistent/map.json"}
    with pytest.raises(ValueError, match=r"bg\.map: cannot read"):
        c.reset(0, 0, params)


def test_lockstep_bg_equals_in_process_bit_for_bit():
    from tests.distributed import run_world

    scenario = load_scenario("bg-exp1").with_overrides(seed=3, max_ticks=240)
    engine = ArenaEngine(scenario)
    expected = engine.run()
    summary, world = run_world(scenario, "bg-lockstep", [("bg", 1, 1)], deadline=60.0)
    np.testing.assert_array_equal(world.pose, engine.world.pose)
    body = [{k: v for k, v in r.items() if k != "map"} for r in expected["robots"]]  # the world's part: no map
    assert summary["robots"] == body and summary["rejected_messages"] == 0
    assert summary["robots"][0]["energy"] < 1.0 and summary["robots"][0]["distance"] > 1.0


def test_a_recording_holds_the_metabolism_the_channels_and_the_map(tmp_path):
    from swarm.recording.arena import ArenaRecorder

    s = load_scenario("bg-exp1").with_overrides(max_ticks=80)
    engine = ArenaEngine(s)
    path = tmp_path / "bg.rrd"
    recorder = ArenaRecorder(path, engine.world, engine.goals, {"run_id": "bg"}, controllers=engine.controllers)
    recorder.close(engine.run(recorder=recorder))
    rows = rrd_rows(path)
    for name in ("energy", "potential", "disorientation", "act", "direction", "motivation/E", "motivation/BKA"):
        assert rows[f"bg/0/{name}"] == 80, name
    assert rows["bg/0/dorsal"] == rows["bg/0/ventral"] == 20  # a bar chart every 4 ticks
    assert rows["world/map/0/nodes"] >= 1 and rows["map/0/belief"] >= 1


def test_an_animat_put_down_on_a_loaded_map_localizes_itself_before_it_plans():
    """Experiments 2 and 3 load a map that another animat made: the test's animat must plan from where it
    is, not from where the mapping animat stopped (that cost a test its first ~30 s, in the wrong way)."""
    from swarm.experiments.girard2005.bg import _with

    maker = ArenaEngine(load_scenario("bg-exp1").with_overrides(max_ticks=600))
    maker.step(600)
    made = maker.controllers[0].map_data()
    assert math.hypot(*made["map"]["nodes"][made["map"]["current"]]["position"]) > 1.5  # it stopped away from start
    engine = ArenaEngine(_with(load_scenario("bg-exp1"), bg={"map": made}, max_ticks=10))
    nav = engine.controllers[0].nav
    assert nav.relocalize
    engine.step(1)
    assert not nav.relocalize and nav.observations == made["observations"]  # localized, nothing mapped yet
    assert math.hypot(*nav.map.nodes[nav.map.current].position) < 1.5  # a node near its start (the map's origin)


def test_sense_reads_the_camera_as_resource_pixels_and_proximity_do():
    """The controller's one compiled pass equals the two readable steps, for every heading and any grey."""
    rng = np.random.default_rng(3)
    levels = np.array([31, 127, 255, 180, 0], np.uint8)
    for _ in range(200):
        grey = rng.choice(levels, size=36, p=[0.2, 0.25, 0.2, 0.3, 0.05]).astype(np.uint8)
        heading = float(rng.uniform(-4 * math.pi, 4 * math.pi))
        prox, seen = sense(grey, heading)
        expected = proximity(resource_pixels(grey, heading))
        assert np.array_equal(prox, expected) and np.array_equal(seen, expected.any(axis=1))
    assert not sense(np.full(36, 180, np.uint8), 0.0)[1].any()


def test_the_plan_cache_key_and_the_selection_sum_are_numpys_to_the_bit():
    """`places._classes` (the plan cache's key and its test) and `gpr._released` (the ventral selection's
    weights and their sum) each replace a few numpy calls a tick and must give numpy's numbers."""
    from agents.controllers.bg.gpr import _released
    from agents.controllers.bg.places import _classes

    rng = np.random.default_rng(8)
    for n in (1, 2, 7, 8, 9, 36, 50, 128):
        for _ in range(50):
            strength = rng.uniform(0, 1, n) * rng.choice([1e-4, 1.0], n)
            classes = np.empty(n)
            assert _classes(strength, classes) == strength.max()
            assert np.array_equal(classes, np.rint(strength * 100))
            d, threshold = rng.normal(0, 1, n), float(rng.uniform(-1, 1))
            w = np.empty(n)
            total = _released(d, threshold, w)
            assert np.array_equal(w, np.maximum(d - threshold, 0.0)) and total == np.maximum(d - threshold, 0.0).sum()
    assert math.isnan(_classes(np.array([0.5, np.nan, 0.2]), np.empty(3)))


def test_with_learn_map_off_an_animat_localizes_on_a_loaded_map_and_leaves_it_as_it_is():
    """`learn_map = false`: the belief follows the animat's views over the loaded map, which gains no node or
    link and whose nodes stay where they were (the belief keeps moving after the first fix)."""
    from swarm.experiments.girard2005.bg import _with

    maker = ArenaEngine(load_scenario("bg-exp1").with_overrides(max_ticks=1200))
    maker.step(1200)
    made = maker.controllers[0].map_data()
    engine = ArenaEngine(
        _with(
            load_scenario("bg-exp1"),
            max_ticks=800,  # Expl everywhere, so that it moves on
            bg={"map": made, "learn_map": False, "navigation": {"known_explore": 1.0}},
        )
    )
    nav = engine.controllers[0].nav
    start = engine.world.pose[0, :2].copy()
    visited, misses, farthest = set(), [], 0.0
    for _ in range(30):  # 75 s, within the part of the room the map knows
        engine.step(10)
        visited.add(nav.map.current)
        here = engine.world.pose[0, :2] - start
        misses.append(math.dist(nav.map.nodes[nav.map.current].position, here))
        farthest = max(farthest, math.hypot(*here))
    assert len(nav.map.nodes) == len(made["map"]["nodes"]) and len(nav.map.links) == len(made["map"]["links"])
    assert [list(n.position) for n in nav.map.nodes] == [n["position"] for n in made["map"]["nodes"]]
    assert nav.observations > made["observations"] + 10 and len(visited) >= 5  # it kept localizing as it moved
    assert farthest > 2.0 and np.median(misses) < 1.0, (farthest, np.round(misses, 1))  # on nodes near where it is


def test_bg_tmaze_experiment_maps_then_tests_and_writes_its_table(tmp_path):
    from swarm.experiments.girard2005.standalone import run_bg_experiment

    result = run_bg_experiment("bg-tmaze", None, 2, 2, 0, tmp_path, ratios=(1.0,), progress=False)
    assert result["runs"] == 2
    for name in ("runs.csv", "summary.csv", "table.md", "plot.png", "maps.json"):
        assert (tmp_path / name).exists(), name
    text = (tmp_path / "table.md").read_text()
    assert "| 1 | 2 (15) |" in text and "| 3 : 12 |" in text and "2 maps" in text  # the paper beside ours
    assert "exp. 3.2, ratio 1: the right branch" in text and "the longer the right branch" not in text  # one ratio
    assert "Seeds 0..1, from the development range: not evidence" in text
    with open(tmp_path / "summary.csv") as f:
        summary = list(csv.DictReader(f))
    assert [r["row"] for r in summary] == ["claim", "table"] and summary[0]["verdict"]
    maps = json.loads((tmp_path / "maps.json").read_text())
    assert len(maps["tmaze-1"]) == 2 and all(len(m["map"]["nodes"]) >= 3 for m in maps["tmaze-1"])
    assert maps["tmaze-1"][0]["map"] != maps["tmaze-1"][1]["map"]  # a map per test: mapping runs with seed + k
    with open(tmp_path / "runs.csv") as f:
        assert sorted(int(row["map"]) for row in csv.DictReader(f)) == [0, 1]  # test k loaded map k


def test_bg_experiment_tests_share_maps_across_conditions():
    from swarm.experiments.girard2005.bg import mapped_floors, test_jobs

    sets = mapped_floors("bg-fear", ("bg-exp3",))
    assert sets == {"bg-exp3": ("bg-exp3", ()), "bg-exp3 without DA": ("bg-exp3", ("DA",))}
    maps = {"bg-exp3": [{"id": 0}, {"id": 1}], "bg-exp3 without DA": [{"id": 2}, {"id": 3}]}
    jobs = test_jobs("bg-fear", 4, 10, maps)
    assert [(j[1], j[3], j[8]) for j in jobs[:8]] == [
        (0.1, 10, 0),
        (0.1, 11, 1),
        (0.1, 12, 0),
        (0.1, 13, 1),
        (0.5, 10, 0),
        (0.5, 11, 1),
        (0.5, 12, 0),
        (0.5, 13, 1),
    ]
    assert all(j[9] is maps["bg-exp3"][j[8]] for j in jobs[:8])
    # the paper's control: the same seeds and Ep, the dangerous area absent from the floor and from its maps,
    # and nothing else changed (F stays the scenario's 0.2)
    control = jobs[8:]
    assert [(j[1], j[3], j[8], j[6]) for j in control] == [
        (f"{ep}, no DA", 10 + k, k % 2, {"potential": ep}) for ep in (0.1, 0.5) for k in range(4)
    ]
    assert all(j[7] == ("DA",) and j[4] == "bg-exp3" and j[9] is maps["bg-exp3 without DA"][j[8]] for j in control)
    assert all(j[5] == {} for j in jobs)  # a test is the declared animat: no [bg] change of its own


def test_bg_choice_runs_the_papers_control_of_ten_tests_without_ep2():
    from swarm.experiments.girard2005.bg import test_jobs

    jobs = test_jobs("bg-choice", 15, 0, {"bg-exp2 without Ep2": [{}]})
    control = [j for j in jobs if j[1] == "no Ep2"]
    assert len(jobs) == 3 * 15 + 10 and len(control) == 10  # the paper's ten
    assert all(j[7] == ("Ep2",) and j[5]["w_plan"] == 0.65 for j in control)
    assert len([j for j in test_jobs("bg-choice", 3, 0, {"bg-exp2 without Ep2": [{}]}) if j[1] == "no Ep2"]) == 3
    assert all(j[4] == "bg-exp2" for j in jobs)  # the floor the map set was made on


def test_a_choice_table_gives_wilson_shares_and_tests_conditions_on_the_same_maps_pairwise():
    """bg-choice's table: each W_plan's Ep1 share with its interval beside the paper's counts; W_plan 0.65
    against 0.45 on the same maps and seeds is McNemar's test, the three together Cochran's Q; the control
    against the paper's 10/10 is Fisher's."""
    from swarm.experiments import stats as S
    from swarm.experiments.girard2005 import sections

    chose = {
        0.65: ["Ep1", "Ep1", "Ep1", "Ep2"],
        0.55: ["Ep1", "Ep2", "Ep1", "none"],
        0.45: ["Ep2", "Ep2", "Ep1", "Ep2"],
    }
    rows = [{"experiment": "bg-choice", "condition": w, "run": k, "chose": c} for w, cs in chose.items()
            for k, c in enumerate(cs)]  # fmt: skip
    rows += [
        {"experiment": "bg-choice", "condition": "no Ep2", "run": k, "chose": c} for k, c in enumerate(["Ep1", "none"])
    ]
    _, table, claims = sections.choice(rows)
    assert "| 0.55 | 4 (15) | 2 | 1 | 1 | 2/4: " + S.proportion_ci(2, 4).text(2) + " | 7 : 8 |" in table
    assert "| no Ep2 (W_plan 0.65) | 2 (10) | 1 | – | 1 |" in table
    ep1 = {w: [c == "Ep1" for c in cs] for w, cs in chose.items()}
    assert claims[0].test == S.mcnemar(ep1[0.65], ep1[0.45]) and claims[0].ours == "3/4 vs 1/4"
    assert claims[1].test == S.cochrans_q([ep1[w] for w in (0.65, 0.55, 0.45)])
    assert claims[2].test == S.fisher(1, 2, 10, 10) and claims[2].expected == 0
    # the most direct paths: bg-forget's by Ep2 is longer than straight to Ep1
    from swarm.experiments.girard2005.bg import direct_seconds

    assert direct_seconds("bg-exp2") > direct_seconds("bg-exp2", ("Ep1",)) > 5.0


def test_the_fear_table_counts_who_died_and_tests_fear_paired_and_against_its_control():
    from swarm.experiments import stats as S
    from swarm.experiments.girard2005 import sections

    tests = {
        0.1: [("Ep1", False), ("none", True), ("none", False)],
        0.5: [("Ep2", False), ("Ep1", False), ("Ep2", False)],
        "0.1, no DA": [("Ep1", False)] * 3,
        "0.5, no DA": [("Ep1", False), ("Ep1", False), ("none", False)],
    }
    rows = [{"experiment": "bg-fear", "condition": ep, "run": k, "chose": c, "died": d} for ep, ts in tests.items()
            for k, (c, d) in enumerate(ts)]  # fmt: skip
    _, table, claims = sections.fear(rows)
    assert "| 0.1 | 3 (20) | 1 | 0 | 2 (1 died) |" in table and "| 0.5 | 3 (20) | 1 | 2 | 0 |" in table
    assert "| 0.5, no DA | 3 (–) | 2 | 0 | 1 | 2/3: " in table and 'Ep1 "systematically"' in table
    assert claims[0].test == S.fisher(1, 1, 1, 3)  # the paper's test, on (Ep1, Ep2)
    assert claims[1].test == S.mcnemar([True, False, False], [False, True, False])  # the same maps and seeds
    assert claims[2].test == S.fisher(2, 3, 1, 3) and claims[2].ours == "2/3 vs 1/3"  # the control's own maps


def test_a_t_maze_ratio_the_paper_did_not_run_shows_a_dash_and_makes_no_claim():
    from swarm.experiments.girard2005 import sections

    branches = {1.0: ["right", "right", "left"], 3.0: ["left", "left", ""]}
    rows = [{"experiment": "bg-tmaze", "condition": r, "run": k, "branch": b} for r, bs in branches.items()
            for k, b in enumerate(bs)]  # fmt: skip
    _, table, claims = sections.tmaze(rows)
    assert "| 1 | 3 (15) | 1 | 2 | 0 |" in table and "| 3 | 3 (–) | 2 | 0 | 1 | 0/2: " in table
    assert table.split("| 3 | 3 (–) |")[1].splitlines()[0].endswith("| – | – |")
    assert [c.text.split(":")[0] for c in claims] == ["exp. 3.2, ratio 1", "exp. 3.2"]
    assert claims[1].paper == "3 → – of 15" and claims[1].ours == "1/3 → 2/2"
    _, _, named = sections.tmaze([{**r, "condition": "my-tmaze"} for r in rows if r["condition"] == 3.0])
    assert named == []  # a floor of the user's, not a ratio: nothing of the paper's to claim


def test_a_bg_forget_table_censors_a_test_that_never_reached_ep1_on_the_users_floor(tmp_path):
    """bg-forget's smoke run on a floor of the user's (bg-exp2 with the start 0.3 m up the corridor): a test
    that has not reloaded at Ep1 by its end counts in the table, censored at its end, not dropped; the
    direct path is that floor's."""
    from swarm.experiments import stats as S
    from swarm.experiments.girard2005 import bg
    from swarm.experiments.girard2005.standalone import run_bg_experiment
    from swarm.scenario import BUNDLED_DIR as BUNDLED

    floor = tmp_path / "my-exp2.toml"
    floor.write_text((BUNDLED / "bg-exp2.toml").read_text().replace('name = "bg-exp2"', 'name = "my-exp2"')
                     .replace("start = [3.0, 0.5,", "start = [3.0, 0.8,"))  # fmt: skip
    result = run_bg_experiment("bg-forget", str(floor), 2, 1, 0, tmp_path / "out", maps=1, mapping_seconds=120.0,
                               progress=False)  # fmt: skip
    with open(tmp_path / "out" / "runs.csv") as f:
        rows = list(csv.DictReader(f))
    reached = np.array([r["chose"] == "Ep1" and r["seconds"] != "" for r in rows])
    assert len(rows) == 2 and not reached.all(), "the smoke's tests should not all reload at Ep1 in time"
    t = [float(r["seconds"]) if ok else bg.TEST_SECONDS for r, ok in zip(rows, reached, strict=True)]
    direct = bg.direct_seconds(str(floor))
    assert round(direct) != round(bg.direct_seconds("bg-exp2"))
    row = next(line for line in result["markdown"].splitlines() if line.startswith("| 2 (15) |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[1].startswith(f"{reached.sum()}/2: ")  # every test counted, the censored ones too
    assert cells[3].split(" [")[0] == f"{S.restricted_mean(t, reached, bg.TEST_SECONDS) - direct:.0f}"
    assert cells[5] == f"{direct:.0f}" and "censored at 900 s" in result["markdown"]
    assert "2 min (mapping" in result["markdown"]


def test_an_exploring_mapping_run_maps_half_an_hour_and_knows_both_ep_where_they_are():
    """Every experiment's mapping (MAPPING_MODES["explore"]): W_plan 0, at least 30 min, then until the
    animat's own map holds every kind of resource on the floor.  The exploring animat knows both Ep, on nodes
    within 1.5 m of each (positions by odometry from the start)."""
    from swarm.experiments.girard2005.bg import MAPPING, build_map
    from swarm.scenario import load_scenario

    assert MAPPING == "explore"
    data = build_map("bg-exp3", 1, ())
    assert data["mapped_seconds"] >= 1800.0 and all(max(data["assoc"][r]) > 0.5 for r in ("Ep", "E", "DA"))
    s = load_scenario("bg-exp3")
    places = np.array([n["position"] for n in data["map"]["nodes"]]) + np.array(s.groups[0].starts[0][:2])
    held = np.array(data["assoc"]["Ep"])
    for name in ("Ep1", "Ep2"):
        centre = next(o.centre for o in s.obstacles if o.name == name)
        near = np.hypot(*(places - np.array(centre)).T) < 1.5
        assert near.any() and held[near].max() > 0.5, name


def test_a_bg_experiment_runs_on_a_floor_given_as_a_file_and_says_what_a_floor_lacks(tmp_path):
    """--scenario FILE: a T-maze of the user's (here tmaze-2's floor under another name) runs as the bundled
    ones do, labelled by its name; a floor without the resources an experiment names is one clear line."""
    from swarm.experiments.girard2005.standalone import run_bg_experiment
    from swarm.scenario import BUNDLED_DIR as BUNDLED

    floor = tmp_path / "my-tmaze.toml"
    floor.write_text((BUNDLED / "tmaze-2.toml").read_text().replace('name = "tmaze-2"', 'name = "my-tmaze"'))
    result = run_bg_experiment("bg-tmaze", str(floor), 2, 2, 0, tmp_path / "out", maps=1, progress=False)
    assert result["runs"] == 2
    with open(tmp_path / "out" / "runs.csv") as f:
        rows = list(csv.DictReader(f))
    assert {r["condition"] for r in rows} == {"my-tmaze"} and all(r["branch"] in ("left", "right", "") for r in rows)
    assert "| my-tmaze | 2 (–) |" in result["markdown"] and "No claim of the paper applies" in result["markdown"]
    lacking = tmp_path / "no-ep2.toml"
    lacking.write_text(floor.read_text().replace('name = "Ep2"', 'name = "Ep3"'))
    with pytest.raises(ScenarioError, match="bg-tmaze needs Ep2") as e:
        run_bg_experiment("bg-tmaze", str(lacking), 2, 1, 0, None, maps=1, progress=False)
    assert "\n" not in str(e.value)
    # a floor that tunes the animat, or runs another experiment's saliences, is refused before any run
    tuned = tmp_path / "tuned.toml"
    tuned.write_text(floor.read_text().replace('saliences = "tmaze"', 'saliences = "tmaze"\ndorsal_threshold = 0.3'))
    untyped = tmp_path / "survival-saliences.toml"
    untyped.write_text(floor.read_text().replace('saliences = "tmaze"', ""))
    for bad, words in [(tuned, "not dorsal_threshold"), (untyped, 'set saliences = "tmaze"')]:
        with pytest.raises(ScenarioError, match=re.escape(words)) as e:
            run_bg_experiment("bg-tmaze", str(bad), 2, 1, 0, None, maps=1, progress=False)
        assert "\n" not in str(e.value)


def test_bg_experiment_maps_option_is_checked():
    from swarm.core.errors import ScenarioError
    from swarm.experiments.girard2005.standalone import run_bg_experiment

    with pytest.raises(ScenarioError, match="--maps"):
        run_bg_experiment("bg-tmaze", None, 2, 1, 0, None, maps=3, progress=False)
    with pytest.raises(ScenarioError, match="--maps"):
        run_bg_experiment("bg-survival", None, 2, 1, 0, None, maps=1, progress=False)
    with pytest.raises(ScenarioError, match="--mapping"):
        run_bg_experiment("bg-survival", None, 2, 1, 0, None, mapping="explore", progress=False)
    with pytest.raises(ScenarioError, match="--mapping: one of hungry, explore"):
        run_bg_experiment("bg-fear", None, 2, 1, 0, None, mapping="sated", progress=False)


def test_bg_experiments_take_bg_settings_to_every_run_and_refuse_unknown_ones():
    import argparse

    from swarm.experiments.girard2005.bg import _with, test_jobs
    from swarm.experiments.girard2005.options import bg_setting as _bg_setting
    from swarm.experiments.girard2005.options import bg_table as _bg_table
    from swarm.experiments.girard2005.standalone import run_bg_experiment

    table = _bg_table([_bg_setting("dorsal_threshold=0.8"), _bg_setting("navigation.anchor=0.2")])
    assert table == {"dorsal_threshold": 0.8, "navigation": {"anchor": 0.2}}
    with pytest.raises(argparse.ArgumentTypeError, match="KEY=VALUE"):
        _bg_setting("anchor")
    engine = ArenaEngine(_with(load_scenario("bg-exp1"), bg={**table, "planning": False}))
    animat = engine.controllers[0]
    assert animat.p.dorsal_threshold == 0.8 and animat.nav.p.anchor == 0.2 and not animat.p.planning
    jobs = test_jobs("bg-choice", 2, 0, {"bg-exp2 without Ep2": [{}]}, table)  # a test's own [bg] fields beside them
    assert all(job[5] == {**table, "w_plan": 0.65 if job[1] == "no Ep2" else job[1],
                          "w_taxon": 0.55} for job in jobs)  # fmt: skip
    with pytest.raises(ScenarioError, match=r"--bg.*bogus"):
        run_bg_experiment("bg-survival", None, 2, 1, 0, None, progress=False, bg={"bogus": 1})
    with pytest.raises(ScenarioError, match=r"--bg: \[bg.navigation\] anchor: expected a number, got true"):
        run_bg_experiment("bg-tmaze", None, 2, 1, 0, None, progress=False, bg={"navigation": {"anchor": True}})
    with pytest.raises(ScenarioError, match=r"bg.navigation.ways: expected one of best, places, got 'every'"):
        run_bg_experiment("bg-fear", None, 2, 1, 0, None, progress=False, bg={"navigation": {"ways": "every"}})
    with pytest.raises(ScenarioError, match=r"bg.navigation.known_explore: expected a number in \[0, 1\], got 2"):
        run_bg_experiment("bg-fear", None, 2, 1, 0, None, progress=False, bg={"navigation": {"known_explore": 2}})


def test_swarm_run_prints_the_animats_metabolism_and_map():
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-m", "swarm", "run", "bg-exp1", "--max-ticks", "40"], capture_output=True,
                         text=True, timeout=300)  # fmt: skip
    assert out.returncode == 0, out.stderr
    assert "alive: E 0.99" in out.stdout and "map:" in out.stdout and "Traceback" not in out.stderr


def test_the_ablation_switches_change_the_animat_and_bad_ones_are_one_clear_line():
    """[bg] feedback = "literal" (eqs. 15-20 as printed), hold_wheels = true (a rule holds the wheels during
    an act), [bg.gpr] cross and dopamine (eq. 10's weight, lambda): each reaches the GPR or the wheels, and
    the declared animat is the default of each."""
    from agents.controllers.bg.controller import bg_params, check_table

    base = controller_params(load_scenario("bg-exp1"), 0)
    animat = BgController()
    animat.reset(0, 0, base)
    assert animat.bg.cross == 0.4 and animat.bg.dopamine == 0.2 and not animat.p.hold_wheels
    assert np.isfinite(animat.bg.ctx_rest_d).all() and (animat.bg.ctx_rest_d > 0.5).all()  # from rest
    ablated = BgController()
    ablated.reset(0, 0, {**base, "bg": {**base["bg"], "feedback": "literal", "hold_wheels": True,
                                        "gpr": {"cross": 0.0, "dopamine": 0.4}}})  # fmt: skip
    assert ablated.bg.cross == 0.0 and ablated.bg.dopamine == 0.4 and ablated.p.hold_wheels
    assert (ablated.bg.ctx_rest_d == 0.0).all()  # the cortex's whole output fed back
    # literally, a salience of 0.1 selects an act outright (why the feedback counts from rest)
    ablated.bg.run(np.array([0.1, 0.0]), np.zeros(36), 2.0)
    assert ablated.bg.disinhibition()[0][0] > 0.9
    animat.bg.run(np.array([0.1, 0.0]), np.zeros(36), 2.0)
    assert animat.bg.disinhibition()[0].max() < 0.0
    for bad, words in [({"feedback": "echo"}, "bg.feedback"), ({"hold_wheels": 1}, "hold_wheels"),
                       ({"gpr": {"tau": 0.04}}, "[bg.gpr]: 'tau' cannot change per run"),
                       ({"gpr": {"cross": "x"}}, "cross")]:  # fmt: skip
        with pytest.raises(ValueError, match=re.escape(words)) as e:
            check_table(bad)
        assert "\n" not in str(e.value)
    assert bg_params({}).feedback == "rest"
