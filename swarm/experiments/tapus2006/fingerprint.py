"""`swarm experiment fingerprint-calibrate | fingerprint-map | fingerprint-localize`:
Tapus, Battaglia & Siegwart (2006), section 3, on the `office` floor.

- calibrate: fingerprints of the mapping tour, every pair labelled same place
  (same ground-truth place zone) or not; a logistic fit of the label on the
  alignment cost per character gives the matching probability's centre and
  width (the defaults of AlignParams come from this command);
- map: the ~76 m mapping tour, a fingerprint every 15 cm (~500), the map's
  nodes against the floor's 20 ground-truth places, and the node count as
  theta varies (the paper: 20 nodes);
- localize: the map of the mapping tour, then each localization tour the
  floor has: `new-path` (~250 m on lines of its own through the mapped
  rooms, the paper's "new path"), `localize` (~253 m, the mapped rooms in
  other orders along the mapping tour's lines): the share of fingerprints
  placed at the right node
  by matching alone (paper 81%) and by the Markov filter (paper 100%: ours
  on the map's odometric grid, and over the links alone beside it), and the
  rank of the right node among the matches when matching alone misses
  (paper: 2nd or 3rd); then the same on the `localize-off-map` tour, which
  also enters the eight rooms the mapping tour did not (our addition: what
  leaving the map costs).

Both at the sensors' specified noise ("low") and with it doubled ("high").
Ground truth (the robot's true pose, the place zones) is read by this module
only, to judge the maps; the controller never sees it.  A node's place is
the place where most of its fingerprints were taken (for the map against
the floor's places).  A fingerprint of the second tour is localized right
when its node holds a mapping fingerprint taken where the nearest one was
(within TOLERANCE more) and, for an aliased node (one holding fingerprints
taken farther apart than one place spans: a false loop closure), only where
the node's place is (right_nodes); fingerprints farther than OFF_MAP from every
mapping fingerprint (off the mapped floor) are left out of the shares
(their count is reported).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from swarm.core.errors import ScenarioError
from swarm.experiments.runner import Outputs, batch_run
from swarm.experiments.tapus2006 import paper

NOISES = ("low", "high")
THETAS = (0.2, 0.35, 0.5, 0.65, 0.8)
PAPER_NODES, PAPER_MATCH, PAPER_MARKOV = paper.NODES, paper.MATCH, paper.MARKOV
LOOP_TOURS = ("localize", "localize-off-map")  # revisiting the mapped rooms, and leaving them: mapped for loops
LOCALIZE_TOURS = ("new-path", *LOOP_TOURS)  # the paper's "new path" first; a floor may lack some
RETRACE = 0.10  # a second-tour fingerprint this close to a mapping fingerprint retraces the mapping tour
OFF_MAP = 1.0  # a fingerprint taken farther than this from every mapping fingerprint is off the mapped floor
TOLERANCE = 0.5  # nodes whose mapping fingerprints lie this much farther than the nearest count as right too


def places(scenario) -> list[tuple[str, tuple[float, float, float, float]]]:
    return [(z.name, z.coords) for z in scenario.zones if z.kind == "place" and z.shape == "rect"]


def place_of(xy: np.ndarray, zones: list) -> int:
    """The place zone holding xy, else the nearest one (door openings lie between zones)."""
    best, where = math.inf, -1
    for k, (_, (x0, y0, x1, y1)) in enumerate(zones):
        dx = max(x0 - xy[0], 0.0, xy[0] - x1)
        dy = max(y0 - xy[1], 0.0, xy[1] - y1)
        d = math.hypot(dx, dy)
        if d < best:
            best, where = d, k
    return where


def place_graph(scenario, door: float = 0.5, gap: float = 0.3) -> set[frozenset[int]]:
    """The floor's place graph: pairs of place zones (indices into places()) that the robot can pass
    between directly, those whose rectangles lie within `gap` of each other along a stretch at least
    `door` wide that no wall blocks (a door, or the corridor going on).  Ground truth, for judging maps."""
    zones = places(scenario)
    walls = [w.coords for w in scenario.walls if w.shape == "rect"]
    graph = set()
    for a, (_, ra) in enumerate(zones):
        for b in range(a + 1, len(zones)):
            rb = zones[b][1]
            for axis in (0, 1):  # the gap lies across `axis`, the shared stretch along the other
                lo, hi = sorted((ra, rb), key=lambda r: r[axis])
                between = hi[axis] - lo[axis + 2]
                other = 1 - axis
                start, end = max(ra[other], rb[other]), min(ra[other + 2], rb[other + 2])
                if not (-1e-9 <= between <= gap) or end - start < door:
                    continue
                mid = (lo[axis + 2] + hi[axis]) / 2
                free = stretch = 0.0
                for t in np.arange(start, end, 0.05):
                    pt = [0.0, 0.0]
                    pt[axis], pt[other] = mid, t
                    blocked = any(w[0] <= pt[0] <= w[2] and w[1] <= pt[1] <= w[3] for w in walls)
                    stretch = 0.0 if blocked else stretch + 0.05
                    free = max(free, stretch)
                if free >= door:
                    graph.add(frozenset((a, b)))
    return graph


def link_topology(run: dict, zones: list, graph: set[frozenset[int]]) -> dict[str, int]:
    """The map's links against the floor's place graph (place_graph), each link's ends at their nodes'
    places (node_places): within one place, between places adjacent on the floor, or between places
    that are not (a link the floor does not have)."""
    labels = node_places(run, zones)
    held = set(run["believed"].tolist())
    same = adjacent = apart = 0
    for a, b, *_ in run["map"]["links"]:
        if a not in held or b not in held:
            continue
        pa, pb = int(labels[a]), int(labels[b])
        same += pa == pb
        adjacent += pa != pb and frozenset((pa, pb)) in graph
        apart += pa != pb and frozenset((pa, pb)) not in graph
    return {"links_same_place": same, "links_adjacent": adjacent, "links_not_adjacent": apart}


def tour_scenario(name: str, route: str, noise: str, seed: int, table: dict | None = None,
                  sensors: dict[str, dict] | None = None, routes: dict | None = None):  # fmt: skip
    """Floor `name` with one fingerprint robot driving `route`: `table` over its [fingerprint] table,
    `sensors` over its sensors' tables ({"camera": {"noise": 10.0}}, as a scenario's [robot.<name>]
    tables), `routes` over the floor's routes."""
    from swarm.scenario import load_scenario

    s = load_scenario(name)
    if getattr(s, "kind", "grid") != "arena":  # a grid scenario has no kind field
        raise ScenarioError(name, "kind", "the fingerprint experiments map an arena floor")
    s = replace(s, routes={**s.routes, **(routes or {})})
    if route not in s.routes:
        tours = ", ".join(repr(t) for t in LOCALIZE_TOURS)
        raise ScenarioError(name, "routes", f"no route {route!r}; the fingerprint experiments need a 'mapping' "
                            f"route and a localization tour ({tours})")  # fmt: skip
    robot = s.groups[0].robot
    for sensor, changes in (sensors or {}).items():
        spec = getattr(robot.sensors, sensor)
        if spec is None:
            raise ScenarioError(name, f"robot.{sensor}", f"the robot {robot.name!r} has no {sensor}")
        robot = replace(robot, sensors=robot.sensors.changed(**{sensor: type(spec).from_table(changes, spec)}))
    g = replace(s.groups[0], count=1, controller="fingerprint", robot=robot, goals=None, draw_goals=False)
    tables = dict(s.controller_params)
    tables["fingerprint"] = {**tables.get("fingerprint", {}), **(table or {})}
    s = replace(s, groups=(g,), controller_params=tables)
    return along(s, route).with_overrides(noise=noise, seed=seed)


def along(s, route: str):
    """Scenario `s` with its one robot driving `route` from its first waypoint, facing the second."""
    first = s.routes[route][0]
    nxt = s.routes[route][1] if len(s.routes[route]) > 1 else (first[0] + 1, first[1])
    heading = math.atan2(nxt[1] - first[1], nxt[0] - first[0])
    return replace(s, groups=(replace(s.groups[0], route=route, starts=((*first, heading),)),))


def drive_tour(s, topomap: dict | None = None, max_ticks: int = 40_000, resume: dict | None = None) -> dict[str, Any]:
    """Run one fingerprint robot along its route; per fingerprint the true pose,
    the node it joined or believed, the node matched best, and the likelihoods.
    With `resume` (a localizing controller's snapshot, the result's "controller"),
    the robot goes on with that controller's map, belief and odometric position
    wherever the route starts: its odometry does not know it was moved."""
    from swarm.engines.arena import ArenaEngine
    from world_server.arena.scenario import controller_params

    engine = ArenaEngine(s)
    c = engine.controllers[0]
    if topomap is not None:
        params = controller_params(s, 0)
        params["fingerprint"] = {**params.get("fingerprint", {}), "mode": "localize"}
        params["topomap"] = topomap
        c.reset(s.seed, 0, params)
        if resume is not None:  # its own driver along its own route, a log of this tour only
            c.restore({**resume, "driver": c.snapshot()["driver"], "log": []})
    truth, likelihoods, prints = [], [], []
    while not c.finished and engine.tick < max_ticks:
        before = engine.world.pose[0].copy()
        seen = len(c.log)
        engine.step(1)
        if len(c.log) > seen:
            truth.append(before)
            likelihoods.append(np.asarray(c.map.likelihood, np.float64).copy())
            prints.append(c.current)
    log = np.array(c.log, np.int64).reshape(-1, 5)
    resolve = np.vectorize(c.map.resolve, otypes=[np.int64])  # a node folded later stands for the one it joined
    believed, matched, by_links = (resolve(log[:, k]) if len(log) else log[:, k] for k in (1, 2, 4))
    return {"ticks": engine.tick, "truth": np.array(truth).reshape(-1, 3), "believed": believed,
            "matched": matched, "believed_links": by_links, "size": c.map.size, "likelihoods": likelihoods,
            "joined": log[:, 1], "nodes_after": log[:, 3],
            "map": c.map_data(),
            "closures": c.map.closures, "fingerprints": prints, "finished": c.finished,
            "wall_seconds": engine.wall_seconds, "controller": c}  # fmt: skip


def node_places(run: dict, zones: list) -> np.ndarray:
    """Each node's place: where most of the fingerprints that joined it were taken."""
    k = len(run["map"]["nodes"])
    counts = np.zeros((k, len(zones)), np.int64)
    for xy, node in zip(run["truth"][:, :2], run["believed"], strict=True):
        counts[node, place_of(xy, zones)] += 1
    return counts.argmax(axis=1)


def judge_map(run: dict, zones: list, graph: set[frozenset[int]] | None = None) -> dict[str, Any]:
    """The map against the floor's places; with the floor's place graph, its links against it too."""
    labels = node_places(run, zones)
    truth = np.array([place_of(xy, zones) for xy in run["truth"][:, :2]])
    visited = set(truth.tolist())
    pure = np.mean(labels[run["believed"]] == truth) if len(truth) else math.nan
    live = np.setdiff1d(np.arange(len(labels)), [a for a, _ in run["map"].get("folded", [])])
    per_place = np.bincount(labels[live], minlength=len(zones))
    rooms = np.array([name.startswith("room") for name, _ in zones], np.bool_)
    first = first_use(run["believed"])
    revisits, closed = room_revisits(truth, first, rooms)
    return {"fingerprints": len(truth), "nodes": run["size"], "places_visited": len(visited),
            "places_with_node": int(sum(per_place[p] > 0 for p in visited)),
            "nodes_per_place": round(run["size"] / max(len(visited), 1), 2), "purity": round(float(pure), 4),
            "links": len(run["map"]["links"]), "closures": run["closures"], "room_revisits": revisits,
            "room_revisits_closed": closed, "false_closures": false_closures(run, zones),
            **closure_scores(run, zones),
            "corridor_seen_again_on_old_node": round(ground_seen_again(run["truth"][:, :2], first, truth, ~rooms),
                                                     4),
            **(link_topology(run, zones, graph) if graph is not None else {})}  # fmt: skip


def far_apart(zones: list) -> float:
    """The distance no one place spans: the diagonal of the floor's largest place zone."""
    return max(math.hypot(x1 - x0, y1 - y0) for _, (x0, y0, x1, y1) in zones)


def aliased_nodes(run: dict, zones: list) -> dict[int, int]:
    """The aliased nodes, each with its place (node_places): nodes holding fingerprints taken farther apart
    than any two points of one place (far_apart), loops closed onto the wrong place, e.g. the corridor's two
    look-alike ends joined in one node.  Ground truth judges the map here; the controller never sees it."""
    far, labels = far_apart(zones), node_places(run, zones)
    xy, nodes = run["truth"][:, :2], run["believed"]
    aliased = {}
    for node in np.unique(nodes):
        p = xy[nodes == node]
        if np.hypot(*(p[:, None, :] - p[None, :, :]).transpose(2, 0, 1)).max() > far:
            aliased[int(node)] = int(labels[node])
    return aliased


def closure_scores(run: dict, zones: list) -> dict[str, Any]:
    """Loop-closure precision (true closures / closures, closure_events) and recall (room revisits
    recalled / room revisits, revisits_recalled); nan where there is nothing to divide."""
    events, true = closure_events(run, zones)
    revisits, recalled = revisits_recalled(run, zones)
    return {"closure_events": events, "true_closures": true, "revisits_recalled": recalled,
            "closure_precision": round(true / events, 4) if events else math.nan,
            "closure_recall": round(recalled / revisits, 4) if revisits else math.nan}  # fmt: skip


def false_closures(run: dict, zones: list) -> int:
    """How many nodes are aliased (aliased_nodes)."""
    return len(aliased_nodes(run, zones))


def closure_events(run: dict, zones: list) -> tuple[int, int]:
    """The map's loop closures judged against ground truth: (closures, true ones).  A closure: a
    fingerprint joined a node that existed before it and is not the node of the fingerprint before
    (the map's `closures`: a move onto a known node, or a young node folded into one).  It is true when
    the robot stood within the place of the node's earlier fingerprints: in the place where most of
    them were taken (a young node folded into it counts not), or within OFF_MAP of one of them."""
    joined, after = run["joined"], run["nodes_after"]
    xy, nodes = run["truth"][:, :2], run["believed"]
    where = np.array([place_of(p, zones) for p in xy], np.int64)
    events = true = 0
    for i in range(1, len(joined)):
        if joined[i] == joined[i - 1] or joined[i] >= after[i - 1]:
            continue
        events += 1
        # the node's fingerprints before, less those of a young node folded into it right here
        earlier = np.flatnonzero((nodes[:i] == nodes[i]) & (joined[:i] != joined[i - 1]))
        if not len(earlier):
            continue
        home = np.bincount(where[earlier]).argmax()
        true += int(home == where[i] or np.hypot(*(xy[earlier] - xy[i]).T).min() <= OFF_MAP)
    return events, true


def revisits_recalled(run: dict, zones: list, least: int = 3) -> tuple[int, int]:
    """The loops the map should close, judged against ground truth: (room revisits, those recalled).  A
    room revisit as in room_revisits; recalled when most of its fingerprints joined nodes made before the
    visit began that hold a fingerprint taken in that room before it (a true closure onto the room)."""
    nodes = run["believed"]
    place = np.array([place_of(p, zones) for p in run["truth"][:, :2]], np.int64)
    rooms = np.array([name.startswith("room") for name, _ in zones], np.bool_)
    first = first_use(nodes)
    recalled = 0
    spans = revisit_spans(place, rooms, least)
    for i, j in spans:
        before = set(nodes[:i][place[:i] == place[i]].tolist())
        recalled += int(np.mean([first[k] < i and int(nodes[k]) in before for k in range(i, j)]) >= 0.5)
    return len(spans), recalled


def first_use(believed: np.ndarray) -> np.ndarray:
    """Per fingerprint, the index of the first fingerprint that joined its node (when the node was made)."""
    first: dict[int, int] = {}
    return np.array([first.setdefault(int(b), i) for i, b in enumerate(believed)], np.int64)


def room_revisits(place: np.ndarray, first: np.ndarray, rooms: np.ndarray, least: int = 3) -> tuple[int, int]:
    """Loops closed where the paper counts them, in rooms: (visits to a room seen on an earlier visit,
    those whose fingerprints mostly joined nodes made before the visit began; `first`: first_use).
    A visit is a run of at least `least` fingerprints in one place."""
    spans = revisit_spans(place, rooms, least)
    return len(spans), sum(int(np.mean(first[i:j] < i) >= 0.5) for i, j in spans)


def revisit_spans(place: np.ndarray, rooms: np.ndarray, least: int) -> list[tuple[int, int]]:
    """[i, j) of every visit to a room seen on an earlier visit, a visit being a run of at least `least`
    fingerprints in one place."""
    seen, spans, i = set(), [], 0
    while i < len(place):
        j = i
        while j < len(place) and place[j] == place[i]:
            j += 1
        if j - i >= least and rooms[place[i]]:
            if place[i] in seen:
                spans.append((i, j))
            seen.add(int(place[i]))
        i = j
    return spans


def ground_seen_again(xy: np.ndarray, first: np.ndarray, place: np.ndarray, where: np.ndarray, near: float = 0.3,
                      lag: int = 20) -> float:  # fmt: skip
    """Of the fingerprints taken within `near` of one taken at least `lag` fingerprints (3 m) earlier, in
    the places marked in `where`, the share that joined a node made before that earlier one's time came
    round again (a node older than `lag` fingerprints): the corridor, where a place zone is 8 m long and
    "a visit" means little, seen again is judged by position."""
    again = old = 0
    for i in range(lag + 1, len(xy)):
        if not where[place[i]] or np.hypot(*(xy[: i - lag] - xy[i]).T).min() > near:
            continue
        again += 1
        old += int(first[i] < i - lag)
    return old / again if again else math.nan


# ------------------------------------------------------------------ jobs


def map_job(job: tuple) -> dict:
    name, noise, seed, theta, route = job
    s = tour_scenario(name, route, noise, seed, {"theta": theta})
    run = drive_tour(s)
    return {"scenario": name, "route": route, "noise": noise, "seed": seed, "theta": theta, "ticks": run["ticks"],
            **judge_map(run, places(s), place_graph(s)), "wall_seconds": round(run["wall_seconds"], 2)}  # fmt: skip


def second_tours(scenario) -> tuple[str, ...]:
    """The localization tours (LOCALIZE_TOURS) that the floor's [routes] hold."""
    return tuple(t for t in LOCALIZE_TOURS if t in scenario.routes)


def localization_tours(scenario, name: str, which: str) -> tuple[str, ...]:
    """The localization tours of floor `name` (`scenario`), for experiment `which`; a floor without one is
    refused in one line."""
    tours = second_tours(scenario)
    if not tours:
        wanted = ", ".join(repr(t) for t in LOCALIZE_TOURS)
        raise ScenarioError(name, "routes", f"no localization tour; {which} needs one of {wanted}")
    return tours


def retracing(mapped_xy: np.ndarray, tour_xy: np.ndarray) -> tuple[int, float]:
    """How closely a second tour follows the mapping tour: (its fingerprints taken within RETRACE of a
    mapping fingerprint, the median distance from one of its fingerprints to the nearest mapping one)."""
    from scipy.spatial import cKDTree

    if not len(mapped_xy) or not len(tour_xy):
        return 0, math.nan
    gap = cKDTree(mapped_xy).query(tour_xy)[0]
    return int((gap <= RETRACE).sum()), float(np.median(gap))


def right_nodes(mapped: dict, xy: np.ndarray, aliased: dict[int, int] | None = None,
                zones: list | None = None) -> set[int] | None:  # fmt: skip
    """The nodes that stand for where `xy` is: those holding a mapping fingerprint taken within TOLERANCE
    of the nearest one, less each aliased node (aliased_nodes: node -> its place) whose place is not the
    place of `xy`: an aliased node is right only at its place, where most of its fingerprints were taken,
    and wrong at the far end it was joined to.  None off the mapped floor (no mapping fingerprint within
    OFF_MAP).  Without `aliased` every node is right wherever it holds a fingerprint (the loose rule)."""
    d = np.hypot(*(mapped["truth"][:, :2] - xy).T)
    if not len(d) or d.min() > OFF_MAP:
        return None
    right = set(mapped["believed"][d <= d.min() + TOLERANCE].tolist())
    if aliased:
        here = place_of(xy, zones)
        right = {n for n in right if aliased.get(n, here) == here}
    return right


def localize_run(name: str, noise: str, seed: int, route: str, table: dict | None = None,
                 sensors: dict[str, dict] | None = None, routes: dict | None = None,
                 second: Callable[..., dict] | None = None, per_print: bool = False) -> tuple[dict, dict]:  # fmt: skip
    """The map of the mapping tour (odometry and sensor noise drawn from `seed`), then the `route` tour
    localizing on it (drawn from seed + 1000): (the mapping run, localization_counts).  `table`,
    `sensors` and `routes` change both tours (tour_scenario); `second(scenario, topomap)` drives the
    second tour (default drive_tour); with `per_print` the counts keep their per-fingerprint `right`."""
    s = tour_scenario(name, "mapping", noise, seed, table, sensors, routes)
    mapped = drive_tour(s)
    tour = tour_scenario(name, route, noise, seed + 1000, table, sensors, routes)
    loc = (second or drive_tour)(tour, mapped["map"])
    counts = localization_counts(mapped, loc, places(s))
    if not per_print:
        del counts["right"]
    return mapped, {**counts, "ticks": loc["ticks"],
                    "finished": loc["finished"],
                    "wall_seconds": round(mapped["wall_seconds"] + loc["wall_seconds"], 2)}  # fmt: skip


def localization_counts(mapped: dict, loc: dict, zones: list) -> dict:
    """Per second tour: how many fingerprints were on the mapped floor, how many of them each of matching
    alone, the grid filter and the links-only filter put at a right node (right_nodes: an aliased node
    counts right only at its own place), the same by the loose rule (`*_right_loose`: an aliased node
    right at both ends), the mean chance of a node drawn at random being right, and where the right node
    ranked among the matches when matching missed; `right`, per fingerprint of the second tour, whether
    matching alone, the grid filter and the links-only filter were right (1) or not (0), -1 off the map."""
    k = mapped["size"]
    aliased = aliased_nodes(mapped, zones)
    by_match, by_markov, by_links, loose, ranks, chance, off = [], [], [], [], [], [], 0
    track = np.full((len(loc["matched"]), 3), -1, np.int8)
    for i, (xy, matched, believed, linked, like) in enumerate(zip(loc["truth"][:, :2], loc["matched"],
                                                                  loc["believed"], loc["believed_links"],
                                                                  loc["likelihoods"], strict=True)):  # fmt: skip
        right = right_nodes(mapped, xy, aliased, zones)
        if right is None:
            off += 1
            continue
        wide = right_nodes(mapped, xy) or set()
        loose.append([int(n) in wide for n in (matched, believed, linked)])
        by_match.append(int(matched) in right)
        by_markov.append(int(believed) in right)
        by_links.append(int(linked) in right)
        track[i] = by_match[-1], by_markov[-1], by_links[-1]
        chance.append(len(right) / k)
        if not by_match[-1] and right:  # where the right node comes among the matches
            order = np.argsort(-like, kind="stable")
            ranks.append(int(np.flatnonzero(np.isin(order, list(right)))[0]) + 1)
    ranks = np.array(ranks, np.int64)
    retraced, gap = retracing(mapped["truth"][:, :2], loc["truth"][:, :2])
    loose_sums = np.array(loose, np.int64).reshape(-1, 3).sum(axis=0)
    return {"map_nodes": k, "fingerprints": len(loc["matched"]), "on_map": len(by_match), "off_map": off,
            "aliased_nodes": len(aliased), "match_right": int(sum(by_match)), "markov_right": int(sum(by_markov)),
            "links_right": int(sum(by_links)), "match_right_loose": int(loose_sums[0]),
            "markov_right_loose": int(loose_sums[1]), "links_right_loose": int(loose_sums[2]),
            "chance": round(float(np.mean(chance)), 4),
            "missed_rank2": int((ranks == 2).sum()), "missed_rank3": int((ranks == 3).sum()),
            "missed_rank_over3": int((ranks > 3).sum()), "retraced": retraced, "gap_median_m": round(gap, 3),
            "right": track}  # fmt: skip


def localize_job(job: tuple) -> dict:
    name, noise, seed, route = job
    _, c = localize_run(name, noise, seed, route)
    share = {f"{key}_correct": round(c[right] / c["on_map"], 4) if c["on_map"] else math.nan
             for key, right in (("match", "match_right"), ("markov", "markov_right"),
                                ("links_markov", "links_right"), ("markov_loose", "markov_right_loose"))}  # fmt: skip
    head = ("map_nodes", "fingerprints", "on_map", "off_map", "aliased_nodes", "retraced", "gap_median_m")
    tail = ("chance", "missed_rank2", "missed_rank3", "missed_rank_over3", "ticks", "finished", "wall_seconds")
    return {"scenario": name, "route": route, "noise": noise, "seed": seed, **{k: c[k] for k in head}, **share,
            **{k: c[k] for k in tail}}  # fmt: skip


def calibration_pairs(name: str, noise: str, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(cost per character, same place) of every pair of the mapping tour's fingerprints."""
    from agents.controllers.fingerprint.align import Matcher, paper_length

    s = tour_scenario(name, "mapping", noise, seed)
    zones = places(s)
    run = drive_tour(s)
    prints = run["fingerprints"]
    where = [place_of(xy, zones) for xy in run["truth"][:, :2]]
    m = Matcher()
    d, same = [], []
    for i in range(len(prints)):
        for j in range(i + 1, len(prints)):
            cost = m.cost(prints[i].codes, prints[j].codes)
            d.append(cost / max(paper_length(prints[i].codes), paper_length(prints[j].codes)))
            same.append(where[i] == where[j])
    return np.array(d), np.array(same, bool)


def fit_logistic(d: np.ndarray, same: np.ndarray) -> tuple[float, float]:
    """(centre, width) of P(same | d) = 1 / (1 + exp((d - centre) / width)), classes weighted equally."""
    from scipy.optimize import minimize

    w = np.where(same, 0.5 / max(same.sum(), 1), 0.5 / max((~same).sum(), 1))

    def loss(x):
        centre, log_width = x
        z = np.clip((d - centre) / math.exp(log_width), -50, 50)
        p = 1.0 / (1.0 + np.exp(z))
        return -np.sum(w * np.where(same, np.log(p + 1e-12), np.log(1 - p + 1e-12)))

    res = minimize(loss, x0=[float(np.median(d)), math.log(0.05)], method="Nelder-Mead")
    return float(res.x[0]), float(math.exp(res.x[1]))


# --------------------------------------------------------------- reports


def _mean(rows: list[dict], key: str) -> float:
    return float(np.mean([r[key] for r in rows])) if rows else math.nan


def run_fingerprint_experiment(which: str, scenario: str | None, reps: int | None, jobs: int | None, seed: int,
                               out: Path | None, progress: bool = True,
                               tours: tuple[str, ...] | None = None) -> dict:  # fmt: skip
    """`tours` keeps fingerprint-localize to those of the floor's localization tours (a smoke run's one)."""
    name = scenario or "office"
    reps = reps or 3
    floor = tour_scenario(name, "mapping", "low", seed)  # a floor it cannot map is refused here, in one line
    if which == "fingerprint-calibrate":
        return _calibrate(name, seed, Outputs(out, which))
    has = localization_tours(floor, name, which) if which == "fingerprint-localize" else second_tours(floor)
    tours = tuple(t for t in has if tours is None or t in tours)
    out = Outputs(out, which)  # (after the floor's tours: a refused floor writes nothing)
    if which == "fingerprint-map":
        work = [(name, noise, seed + r, theta, "mapping") for noise in NOISES for r in range(reps) for theta in THETAS]
        work += [(name, noise, seed + r, 0.5, route) for route in LOOP_TOURS if route in tours for noise in NOISES
                 for r in range(reps)]  # loops  # fmt: skip
        rows = batch_run(map_job, work, jobs=jobs, desc=which, progress=progress)
        rows.sort(key=lambda r: (("mapping", *LOOP_TOURS).index(r["route"]), NOISES.index(r["noise"]), r["theta"],
                                 r["seed"]))  # fmt: skip
        md = _map_table(rows, name, reps, seed)
        plot_map(rows, name, seed, out / "plot.png")
    elif which == "fingerprint-localize":
        work = [(name, noise, seed + r, route) for route in tours for noise in NOISES for r in range(reps)]
        rows = batch_run(localize_job, work, jobs=jobs, desc=which, progress=progress)
        rows.sort(key=lambda r: (LOCALIZE_TOURS.index(r["route"]), NOISES.index(r["noise"]), r["seed"]))
        md = _localize_table(rows, name, reps, seed)
        plot_localize(rows, out / "plot.png")
    else:
        raise ValueError(f"unknown fingerprint experiment {which!r}")
    out.runs(rows)
    summarized = ("mapping",) if which == "fingerprint-map" else tours
    summary = [{"route": t, "noise": n,
                **{k: round(_mean([r for r in rows if r["noise"] == n and r["route"] == t and
                                   (which != "fingerprint-map" or r["theta"] == 0.5)], k), 4)
                   for k in rows[0] if isinstance(rows[0][k], (int, float)) and k != "seed"}}
               for t in summarized for n in NOISES]  # fmt: skip
    return out.finish(summary, md)


def _revisits(rows: list[dict]) -> str:
    n = _mean(rows, "room_revisits")
    return f"{_mean(rows, 'room_revisits_closed'):.1f} / {n:.1f}" if n > 0 else "–"


def _share(x: float) -> str:
    return "–" if math.isnan(x) else f"{x:.1%}"


def _map_table(rows: list[dict], name: str, reps: int, seed: int) -> str:
    tour = [r for r in rows if r["route"] == "mapping"]
    lines = [f"# Fingerprint mapping (Tapus et al. 2006), `{name}`\n",
             f"{reps} runs per noise level and theta (seeds {seed}..{seed + reps - 1}).  The mapping tour passes "
             f"{tour[0]['places_visited']} of the floor's places.\n",
             "| tour | noise | theta | fingerprints | nodes | paper | places with a node | nodes per place | "
             "purity | loops closed | room revisits closed | corridor seen again: on an old node |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for route in ("mapping", *LOOP_TOURS):
        for noise in NOISES:
            for theta in THETAS:
                sel = [r for r in rows if r["route"] == route and r["noise"] == noise and r["theta"] == theta]
                if not sel:
                    continue
                paper = PAPER_NODES if theta == 0.5 and route == "mapping" else ""
                lines.append(f"| {route} | {noise} | {theta} | {_mean(sel, 'fingerprints'):.0f} | "
                             f"{_mean(sel, 'nodes'):.1f} | {paper} | {_mean(sel, 'places_with_node'):.1f} / "
                             f"{sel[0]['places_visited']} | {_mean(sel, 'nodes_per_place'):.2f} | "
                             f"{_mean(sel, 'purity'):.3f} | {_mean(sel, 'closures'):.1f} | {_revisits(sel)} | "
                             f"{_share(_mean(sel, 'corridor_seen_again_on_old_node'))} |")  # fmt: skip
    lines.append("\nPurity: the share of fingerprints whose node's place (where most of its fingerprints were "
                 "taken) is where they were taken.  The localization tours (~255 m) enter rooms two and three times "
                 "(`localize` the mapping tour's eight, `localize-off-map` all sixteen): mapped with one, a place "
                 "seen again should join its node (a loop closed), not add one.  Room revisits closed: visits (3 "
                 "fingerprints or more) to a room seen on an earlier visit whose fingerprints mostly joined nodes "
                 "made before the visit (the paper's loops: its robot closed them all).  Corridor seen again: of "
                 "the fingerprints taken within 0.3 m of one taken 3 m of travel or more earlier, the share that "
                 "joined a node made before then.  The "
                 "paper's theta is not given (\"determined experimentally\"); ours is 0.5, the calibrated "
                 "probability's even odds.")  # fmt: skip
    return "\n".join(lines) + "\n"


def _localize_table(rows: list[dict], name: str, reps: int, seed: int) -> str:
    lines = [
        f"# Fingerprint localization (Tapus et al. 2006), `{name}`\n",
        f"Map from the mapping tour, then a localization tour; {reps} runs per tour and noise level "
        f"(seeds {seed}..{seed + reps - 1}).\n",
        "| tour | noise | map nodes | fingerprints (on the map) | retracing | matching alone | paper | Markov filter | "
        "paper | links only | chance | misses by matching: right node 2nd / 3rd / lower |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for route in LOCALIZE_TOURS:
        for noise in NOISES:
            sel = [r for r in rows if r["noise"] == noise and r["route"] == route]
            if not sel:
                continue
            m, k = _mean(sel, "match_correct"), _mean(sel, "markov_correct")
            lines.append(f"| {route} | {noise} | {_mean(sel, 'map_nodes'):.1f} | {_mean(sel, 'fingerprints'):.0f} "
                         f"({_mean(sel, 'on_map'):.0f}) | {_share(_mean(sel, 'retraced') / _mean(sel, 'fingerprints'))}"
                         f", median {_mean(sel, 'gap_median_m'):.2f} m | {m:.1%} | {PAPER_MATCH:.0%} "
                         f"({m - PAPER_MATCH:+.1%}) | "
                         f"{k:.1%} | {PAPER_MARKOV:.0%} ({k - PAPER_MARKOV:+.1%}) | "
                         f"{_mean(sel, 'links_markov_correct'):.1%} | {_mean(sel, 'chance'):.1%} | "
                         f"{_mean(sel, 'missed_rank2'):.0f} / {_mean(sel, 'missed_rank3'):.0f} / "
                         f"{_mean(sel, 'missed_rank_over3'):.0f} |")  # fmt: skip
    lines.append(f"\nRight: the node holds a mapping fingerprint taken where the nearest one was (within "
                 f"{TOLERANCE} m more); fingerprints farther than {OFF_MAP} m from every mapping fingerprint (the "
                 "rooms the mapping tour did not enter) are left out.  Markov filter: the belief on the map's "
                 "odometric grid (the controller's default); links only: the same likelihoods through the "
                 "link-only motion model.  The paper's robot stayed on its map on \"a new path\" (`new-path`: "
                 "lines of its own through the mapped rooms); `localize` retraces the mapping tour's lines; "
                 "`localize-off-map` also enters the eight rooms the mapping tour did not.  Retracing: the share "
                 f"of the tour's fingerprints taken within {RETRACE:.2f} m of a mapping fingerprint, and the median "
                 "distance to the nearest one.  Chance: a node "
                 "drawn at random.  The paper's floor and tours are not available; ours are in "
                 "docs/fingerprint.md.")  # fmt: skip
    return "\n".join(lines) + "\n"


def _calibrate(name: str, seed: int, out: Outputs) -> dict:
    rows, fits = [], []
    for noise in NOISES:
        d, same = calibration_pairs(name, noise, seed)
        centre, width = fit_logistic(d, same)
        fits.append((noise, centre, width, int(same.sum()), int((~same).sum())))
        rows.append({"noise": noise, "centre": round(centre, 4), "width": round(width, 4),
                     "same_pairs": int(same.sum()), "different_pairs": int((~same).sum()),
                     "same_d_median": round(float(np.median(d[same])), 4),
                     "different_d_median": round(float(np.median(d[~same])), 4)})  # fmt: skip
    out.runs(rows)
    md = ["# Calibrating P(match) on `" + name + "` (mapping tour, every pair of fingerprints)\n",
          "| noise | centre | width | same-place pairs | different-place pairs | median d, same | "
          "median d, different |",
          "|---|---|---|---|---|---|---|"]  # fmt: skip
    md += [f"| {r['noise']} | {r['centre']} | {r['width']} | {r['same_pairs']} | {r['different_pairs']} | "
           f"{r['same_d_median']} | {r['different_d_median']} |" for r in rows]  # fmt: skip
    md.append(
        "\nd: alignment cost per character of the longer fingerprint.  "
        "P(match) = 1 / (1 + exp((d - centre) / width)), fitted by weighted logistic regression."
    )
    return out.finish(None, "\n".join(md) + "\n")


def plot_map(rows: list[dict], name: str, seed: int, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(15, 5), gridspec_kw={"width_ratios": [1, 2.2]})
    for noise in NOISES:
        means = [_mean([r for r in rows if r["route"] == "mapping" and r["noise"] == noise and r["theta"] == t],
                       "nodes") for t in THETAS]  # fmt: skip
        axes[0].plot(THETAS, means, "o-", label=f"noise {noise}")
    axes[0].axhline(PAPER_NODES, color="grey", ls="--", label="paper (its floor)")
    axes[0].set(xlabel="theta", ylabel="nodes", title="nodes as theta varies")
    axes[0].legend()
    s = tour_scenario(name, "mapping", "low", seed)
    run = drive_tour(s)
    draw_map(axes[1], s, run)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def draw_map(ax, s, run: dict) -> None:
    """The map over the floor plan: each node at the mean true position of its
    fingerprints (display only), links between them, the tour."""
    for wall in s.walls:
        c = wall.coords
        if wall.shape == "rect":
            ax.add_patch(__import__("matplotlib.patches", fromlist=["Rectangle"]).Rectangle(
                (c[0], c[1]), c[2] - c[0], c[3] - c[1], color=np.array(wall.colour) / 255))  # fmt: skip
        else:
            ax.plot([c[0], c[2]], [c[1], c[3]], color=np.array(wall.colour) / 255)
    xy, nodes = run["truth"][:, :2], run["believed"]
    ax.plot(xy[:, 0], xy[:, 1], color="#bbb", lw=0.8, zorder=1)
    live = [i for i in range(len(run["map"]["nodes"])) if (nodes == i).any()]  # folded nodes hold none
    centres = {i: xy[nodes == i].mean(axis=0) for i in live}
    k = len(live)
    for a, b, *_ in run["map"]["links"]:
        if a in centres and b in centres:
            ax.plot([centres[a][0], centres[b][0]], [centres[a][1], centres[b][1]], color="#36c", lw=1.2, zorder=2)
    ax.scatter([c[0] for c in centres.values()], [c[1] for c in centres.values()], s=40, color="#c33", zorder=3)
    ax.set(aspect="equal", xlim=(0, s.size[0]), ylim=(0, s.size[1]),
           title=f"{k} nodes over the floor plan (noise {s.noise.level}, theta 0.5)")  # fmt: skip


def plot_localize(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 5.2))
    groups = [(route, n) for route in LOCALIZE_TOURS for n in NOISES if any(r["route"] == route for r in rows)]
    x = np.arange(len(groups))
    bars = (("match_correct", "matching alone"), ("links_markov_correct", "Markov, links only"),
            ("markov_correct", "Markov filter (grid)"))  # fmt: skip
    for i, (key, label) in enumerate(bars):
        ax.bar(x + (i - 1) * 0.27, [_mean([r for r in rows if (r["route"], r["noise"]) == g], key) for g in groups],
               0.27, label=label)  # fmt: skip
    ax.axhline(PAPER_MATCH, color="C0", ls="--", lw=1, label="paper, matching (81%)")
    ax.axhline(PAPER_MARKOV, color="C2", ls="--", lw=1, label="paper, Markov (100%)")
    ax.plot(x, [_mean([r for r in rows if (r["route"], r["noise"]) == g], "chance") for g in groups], "k_", ms=30,
            label="chance")  # fmt: skip
    ax.set(xticks=x, xticklabels=[f"{route}\nnoise {n}" for route, n in groups], ylim=(0, 1.05),
           ylabel="share at the right place", title="localization on the second tour")  # fmt: skip
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=3, fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
