"""Filliat-style navigation for the BG animat (Girard et al. 2005, section
2.1) on the shared topological map (agents/controllers/navigation/topomap.py).

A place is what the animat perceives there, turned allocentric by the
compass: 36 grey levels of the panoramic camera and 8 sonar ranges.  On top
of the map this module keeps what the BG model asks of the navigation
system:

- Disorientation D in [0, 1]: up by `d_rise` of the way to 1 each time a new
  node is made, down by the factor `d_fall` at each observation in a node
  known before the current visit (the paper: "D increases when the robot is
  creating new nodes and only decreases when it spends time in well known
  areas"); a node is known once `known_age` observations have passed since
  it was made: coming back to it is coming back to a known area;
- resources learned per node by a Hebbian rule with forgetting: while a
  resource is usable, dw = `gain` * dt * b(node) * (1 - w); while it is not
  even in sight, dw = -`forget` * dt * b(node) * w (a place that held it, where
  it cannot be seen, has lost it: an exhausted resource is forgotten, not a
  resource merely out of reach);
- P(res): shortest routes over the links from every node that holds res,
  weighted by what it holds and by exp(-distance / `reach`), give the
  proximity of res from the current node; its direction is that of the
  route's first `lookahead` metres (summed link displacements) or, with
  `pursuit`, from where the last observation was made to the first node of
  the route that far away (the next place on the way: no corner cut through
  a wall's end); spread over the 36 directions by a von Mises bump;
- odometry (compass-turned) drifts, some 1.5 m over 80 minutes of bg-exp1:
  with `anchor`, each time the animat recognizes a place (joins or closes a
  loop onto a node it had), its odometric position is pulled that share of
  the way to the node's, so the map and the animat stay in one frame;
- BKA: P towards the known nodes (made `known_age` observations ago or more);
- Expl: the directions in which the sonars see room and the map has no node
  near yet, plus a slowly turning random preference (random exploration
  finds what no map knows about).
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from agents.controllers.bg.params import NavParams
from agents.controllers.bg.senses import to_allocentric
from agents.controllers.navigation.dijkstra import shortest_routes
from agents.controllers.navigation.params import MapParams
from agents.controllers.navigation.topomap import TopoMap, topomap_from_data, topomap_to_data
from swarm.core.kernels import exported, njit
from swarm.core.rng import fill_uniform

DIRECTIONS = 36
ANGLES = np.arange(DIRECTIONS) * (2 * math.pi / DIRECTIONS)
S_EXPLORE = 101  # noise stream of the exploration preference


class PlaceSignatures:
    """Grey panorama (36) + sonar (8), allocentric; P(match) = exp(-mean squared scaled difference)."""

    def __init__(self, grey_scale: float, sonar_scale: float):
        self.gs, self.ss = grey_scale, sonar_scale
        self._rows = np.zeros((0, DIRECTIONS + 8))  # np.stack of the means last asked about ...
        self._held: list[Any] = []  # ... and the arrays they were copied from

    def likelihoods(self, observation: Any, means: list[Any]) -> np.ndarray:
        if not means:
            return np.zeros(0)
        m = self._stacked(means)
        g = ((m[:, :DIRECTIONS] - observation[:DIRECTIONS]) / self.gs) ** 2
        s = ((m[:, DIRECTIONS:] - observation[DIRECTIONS:]) / self.ss) ** 2
        return np.exp(-0.5 * (g.mean(axis=1) + s.mean(axis=1)))

    def mean(self, members: list[Any]) -> Any:
        return np.mean(members, axis=0)

    def _stacked(self, means: list[Any]) -> np.ndarray:
        """np.stack(means), copying only the rows whose array is not the one copied last time: a map
        changes a node's mean at a time, and always by a new array (never in place), so the rest hold."""
        if len(means) > len(self._rows):
            grown = np.zeros((max(2 * len(self._rows), len(means), 16), DIRECTIONS + 8))
            grown[: len(self._rows)] = self._rows
            self._rows = grown
        held = self._held
        for i, mean in enumerate(means):
            if i >= len(held):
                held.append(mean)
                self._rows[i] = mean
            elif held[i] is not mean:
                held[i] = mean
                self._rows[i] = mean
        return self._rows[: len(means)]


def bump(direction: float, strength: float, width: float) -> np.ndarray:
    """A von Mises bump over the 36 directions, peak `strength` at `direction`."""
    return strength * np.exp(width * (np.cos(ANGLES - direction) - 1.0))


@functools.cache
def _bump_at(channel: int, width: float) -> np.ndarray:
    return bump(ANGLES[channel], 1.0, width)


def _channel_bump(channel: int, width: float) -> np.ndarray:
    """bump(ANGLES[channel], 1, width), worked out once per channel: the exploration vector is one of these."""
    return _bump_at(channel, width).copy()


@exported("bg_hebbian", "void(float64[::1], float64[::1], float64, boolean)")
@njit(cache=True)
def _hebbian(w: np.ndarray, b: np.ndarray, rate: float, usable: bool) -> None:
    """In place: w += min(rate b, 1) (1 - w) while usable, else w -= rate b w (numpy's numbers, to the bit)."""
    for i in range(w.shape[0]):
        if usable:
            w[i] += min(rate * b[i], 1.0) * (1.0 - w[i])
        else:
            w[i] -= rate * b[i] * w[i]


@exported("bg_classes", "float64(float64[::1], float64[::1])")
@njit(cache=True)
def _classes(strength: np.ndarray, classes: np.ndarray) -> float:
    """classes = np.rint(strength * 100); returns strength.max() (nan if any is): one call, every tick."""
    most = -np.inf
    for i in range(strength.shape[0]):
        v = strength[i]
        classes[i] = np.rint(v * 100)
        if v != v:
            most = np.nan
        elif v > most:
            most = v
    return most


_SONAR_ANGLES = np.arange(9) * (2 * math.pi / 8)  # the 8 sonars' directions, the first again at 360 degrees


@exported("bg_explore_channel", "int64(float64[::1], float64, float64[::1], float64[::1])")
@njit(cache=True)
def _explore_channel(sonar: np.ndarray, open_range: float, novel: np.ndarray, wander: np.ndarray) -> int:
    """The direction channel with most room (the 8 allocentric sonar ranges interpolated over the 36
    channels), novelty and wander, -1 if none has any: what numpy's interp, clip and argmax gave, to the
    bit (interp's formula and its exact-node case as numpy/_core/src/multiarray/compiled_base.c has them)."""
    best, best_score = -1, 0.0
    for k in range(DIRECTIONS):
        x = ANGLES[k]
        j = 0
        while j < 7 and _SONAR_ANGLES[j + 1] <= x:
            j += 1
        lo, hi = sonar[j], sonar[(j + 1) % 8]
        if _SONAR_ANGLES[j] == x:
            room = lo
        else:
            room = (hi - lo) / (_SONAR_ANGLES[j + 1] - _SONAR_ANGLES[j]) * (x - _SONAR_ANGLES[j]) + lo
        o = room / open_range - 0.5
        o = 1.0 if o > 1.0 else (0.0 if o < 0.0 else o)
        score = o * (0.5 * novel[k] + wander[k])
        if score > best_score:
            best, best_score = k, score
    return best


class Navigator:
    def __init__(self, params: NavParams, seed: int, agent: int, resources: tuple[str, ...], mapping: bool = True):
        self.p, self.seed, self.agent = params, seed, agent
        self.mapping = mapping  # make and move nodes (False: only localize on the map as it is)
        self.map = TopoMap(PlaceSignatures(params.grey_scale, params.sonar_scale),
                           MapParams(theta=params.theta, closure_match=params.closure_match, near=params.near,
                                     recent=params.recent, closure_radius=params.closure_radius,
                                     merge_match=params.merge_match))  # fmt: skip
        self.born: list[int] = []  # observation count at each node's creation
        self.observations = 0
        self.resources = resources
        self.assoc: dict[str, np.ndarray] = {r: np.zeros(0) for r in resources}
        self.xy = np.zeros(2)  # odometric position (compass-turned odometry)
        self.since = np.zeros(2)  # displacement since the last observation
        self.at = np.zeros(2)  # odometric position of the last observation (where routes start from)
        self.D = 0.0
        self.created = 0
        self.relocalize = False
        self._edge_key: tuple = ()
        self._edge_cache: tuple[np.ndarray, np.ndarray, np.ndarray] = ()  # type: ignore[assignment]
        self._towards: dict[tuple, np.ndarray] = {}  # P vectors, until the map or what nodes hold changes
        self._novel_key: tuple = ()
        self._novel = np.ones(DIRECTIONS)
        self._wander_key = -1
        self._known_key: tuple = ()
        self._known = np.zeros(0)
        self._wander = np.zeros(DIRECTIONS)
        self.news = 0  # changes from other animats (their nodes, links, what nodes hold): caches key on it too

    # ----------------------------------------------------------- sensing

    def move(self, forward: float, heading: float) -> None:
        dx, dy = forward * math.cos(heading), forward * math.sin(heading)  # new arrays: others may hold the old
        self.xy = np.array((self.xy[0] + dx, self.xy[1] + dy))
        self.since = np.array((self.since[0] + dx, self.since[1] + dy))

    def due(self) -> bool:
        """Time for an observation: every `spacing` metres, on an empty map, and at once when put down on a
        map (a test's first plan must start from where the animat is, not from where the map was left)."""
        return self.relocalize or float(np.hypot(self.since[0], self.since[1])) >= self.p.spacing or not self.map.nodes

    def lost(self) -> None:
        """The animat was put down somewhere on a map it has (a loaded one): the next observation
        localizes it by matching alone, and its odometric frame is re-anchored on that node."""
        self.relocalize = True

    def observe(self, grey: np.ndarray, sonar: np.ndarray, heading: float) -> int:
        """Map one place (every `spacing` metres): join, close a loop or create a node; D follows."""
        observation = np.concatenate([to_allocentric(grey.astype(np.float64), heading), to_allocentric(sonar, heading)])
        if self.relocalize and self.map.nodes:
            self.map.belief = np.full(len(self.map.nodes), 1.0 / len(self.map.nodes))
            _, belief = self.map.localize(observation, np.zeros(2))
            node = int(np.argmax(belief))
            self.map.current, self.map.belief = node, np.eye(len(self.map.nodes))[node]
            self.xy, self.since, self.relocalize = self.map.nodes[node].position.copy(), np.zeros(2), False
            self.at = self.xy.copy()
            return node
        if not self.mapping:  # a map that stays as it is: the belief follows the view, no node is made or moved
            _, belief = self.map.localize(observation, self.since)
            self.map.current = int(np.argmax(belief))
            self.since, self.at = np.zeros(2), self.xy.copy()
            self.observations += 1
            self.D *= self.p.d_fall
            return self.map.current
        before, folded = len(self.map.nodes), len(self.map.folded)
        node = self.map.observe(observation, self.xy, self.since, self.p.extent)
        if len(self.map.folded) > folded:  # a young node turned out to be a known place: what it held goes there
            for young, known in list(self.map.folded.items())[folded:]:
                for w in self.assoc.values():
                    w[known], w[young] = max(w[known], w[young]), 0.0
        self.since, self.at = np.zeros(2), self.xy.copy()
        self.observations += 1
        self.born += [self.observations] * (len(self.map.nodes) - before)
        if len(self.map.nodes) > before:
            self.created += 1
            self.D += self.p.d_rise * (1.0 - self.D)
            for r in self.resources:
                self.assoc[r] = np.concatenate([self.assoc[r], np.zeros(len(self.map.nodes) - len(self.assoc[r]))])
        else:  # a known place (with `anchor`, odometry is pulled part of the way to where the map has it)
            if self.observations - self.born[node] >= self.p.known_age:
                self.D *= self.p.d_fall
            if self.p.anchor > 0.0:
                self.xy = self.xy + self.p.anchor * (self.map.nodes[node].position - self.xy)
                self.at = self.xy.copy()
        return node

    def grow(self) -> None:
        """Nodes another animat's map brought in (agents/controllers/navigation/mapshare.py): they hold
        nothing until told, and count as known (their maker has been there: coming into one is coming
        into a known area)."""
        added = len(self.map.nodes) - len(self.born)
        if added > 0:
            self.born += [self.observations - self.p.known_age] * added
            for r in self.resources:
                self.assoc[r] = np.concatenate([self.assoc[r], np.zeros(added)])
        self.news += 1

    def learn(self, usable: dict[str, bool], seen: dict[str, bool], dt: float) -> None:
        """Hebbian association of the believed nodes with the resources usable there, and forgetting:
        a node believed to hold a resource that is not even in sight from there loses it."""
        b = self.map.belief
        if len(b) == 0:
            return
        b = np.ascontiguousarray(b, np.float64)
        for r in self.resources:
            if usable.get(r):
                _hebbian(self.assoc[r], b, self.p.gain * dt, True)
            elif not seen.get(r):
                _hebbian(self.assoc[r], b, self.p.forget * dt, False)

    # ----------------------------------------------------------- vectors

    def _edges(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(from, to, length) of every link both ways, rebuilt only when the links change."""
        key = (len(self.map.nodes), len(self.map.links), self.observations, self.news)
        if self._edge_key != key:
            ab = np.array(list(self.map.links), np.int64).reshape(-1, 2)
            shift = np.array([link.displacement for link in self.map.links.values()]).reshape(-1, 2)
            d = np.maximum(np.hypot(shift[:, 0], shift[:, 1]), 1e-3)  # each Link.distance, floored
            self._edge_cache = (np.concatenate([ab[:, 0], ab[:, 1]]), np.concatenate([ab[:, 1], ab[:, 0]]),
                                np.concatenate([d, d]))  # fmt: skip
            self._edge_key = key
        return self._edge_cache

    def towards(self, strength: np.ndarray, each_place: bool = False) -> np.ndarray:
        """36-vector pointing along the route to the nodes of largest strength * exp(-route / reach); with
        `each_place`, the largest of such vectors to each place (`_places`): every place holding a resource
        pulls its own way, as eq. 1's "proximity of that resource in 36 directions" reads."""
        k = len(self.map.nodes)
        here = self.map.current
        if k == 0 or here < 0 or len(strength) == 0:
            return np.zeros(DIRECTIONS)
        classes = np.empty(len(strength))  # np.round(strength, 2)'s classes key the cache
        if not _classes(np.ascontiguousarray(strength, np.float64), classes) > 1e-3:
            return np.zeros(DIRECTIONS)
        key = (self.observations, self.news, here, classes.tobytes(), each_place)
        if key in self._towards:
            return self._towards[key]
        sources = np.flatnonzero(strength > 1e-3)  # a virtual source k reaches each by what it holds
        if each_place:
            out = np.zeros(DIRECTIONS)
            for place in self._places(sources, strength):
                np.maximum(out, self._route_bump(place, strength), out=out)
        else:
            out = self._route_bump(sources, strength)
        if len(self._towards) > 64:
            self._towards.clear()
        self._towards[key] = out
        return out

    def _route_bump(self, sources: np.ndarray, strength: np.ndarray) -> np.ndarray:
        """A bump along the best route from here to any of `sources`, of height strength * exp(-route / reach)
        (zeros when no route leads there, or here is where it leads: the last stretch is the taxon's)."""
        k, here = len(self.map.nodes), self.map.current
        rows, cols, lengths = self._edges()
        dist, pred = shortest_routes(k + 1, k, np.concatenate([rows, np.full(len(sources), k)]),
                                     np.concatenate([cols, sources]),
                                     np.concatenate([lengths, -self.p.reach * np.log(strength[sources])]))  # fmt: skip
        if not np.isfinite(dist[here]):
            return np.zeros(DIRECTIONS)
        offset = self._next_place(pred, k) if self.p.pursuit > 0.0 else self._first_metre(pred, k)
        if offset is None:
            return np.zeros(DIRECTIONS)
        return bump(math.atan2(offset[1], offset[0]), math.exp(-dist[here] / self.p.reach), self.p.width)

    def _places(self, sources: np.ndarray, strength: np.ndarray) -> list[np.ndarray]:
        """`sources` grouped into places: strongest first, each joins the first place whose first node lies
        within `place_radius` (the nodes round one resource are one place, not one bump each)."""
        firsts: list[np.ndarray] = []
        places: list[list[int]] = []
        for n in sources[np.argsort(-strength[sources], kind="stable")]:
            at = self.map.nodes[n].position
            for place, first in zip(places, firsts, strict=True):
                if math.hypot(at[0] - first[0], at[1] - first[1]) < self.p.place_radius:
                    place.append(int(n))
                    break
            else:
                firsts.append(at)
                places.append([int(n)])
        return [np.array(place, np.int64) for place in places]

    def _first_metre(self, pred: np.ndarray, source: int) -> np.ndarray | None:
        """The route's link displacements summed over its first `lookahead` metres (None: no way to go).
        Round a wall's end this cuts the corner (docs/bg.md, Experiment 1): see `_next_place`."""
        offset, node, travelled = np.zeros(2), self.map.current, 0.0
        while pred[node] != source and pred[node] >= 0 and travelled < self.p.lookahead:
            nxt = int(pred[node])
            d = self._displacement(node, nxt)
            offset, travelled, node = offset + d, travelled + float(np.hypot(*d)), nxt
        return offset if travelled > 0.0 else None

    def _next_place(self, pred: np.ndarray, source: int) -> np.ndarray | None:
        """From where the last observation was made (the route starts there too) to the first node of the
        route at least `pursuit` away: the next place the animat has been to on the way.  That place stays
        put between observations, so the vector is cached with the route and a restored animat, whose cache
        is empty, works out the same one."""
        node, offset = self.map.current, None
        while pred[node] != source and pred[node] >= 0:
            node = int(pred[node])
            offset = self.map.nodes[node].position - self.at
            if math.hypot(offset[0], offset[1]) >= self.p.pursuit:
                break
        return offset

    def _displacement(self, a: int, b: int) -> np.ndarray:
        key = (min(a, b), max(a, b))
        d = self.map.links[key].displacement
        return d if a < b else -d

    def plan(self, resource: str) -> np.ndarray:
        return self.towards(self.assoc[resource], self.p.ways == "places")

    def back_to_known(self) -> np.ndarray:
        if self._known_key != (self.observations, len(self.born)):  # it changes only with these
            self._known = (self.observations - np.array(self.born) >= self.p.known_age).astype(np.float64)
            self._known_key = (self.observations, len(self.born))
        known = self._known
        if len(known) and self.map.current >= 0 and known[self.map.current]:
            return np.zeros(DIRECTIONS)
        return self.towards(known)

    def explore(self, sonar: np.ndarray, heading: float, time: float, use_map: bool) -> np.ndarray:
        """A bump at the direction to explore: where the sonars see room, the map has no node near
        yet, and a random preference (turning every `wander_period` seconds, drawn from seed, agent and
        that period's index) points.  One bump, not a broad profile: a broad salience over the 36
        channels excites the diffuse STN so much that no channel is released (docs/bg.md)."""
        if self._novel_key != (self.observations, self.news, use_map):  # coverage changes only with these
            self._novel = self._novelty(use_map)
            self._novel_key = (self.observations, self.news, use_map)
        period = int(time // self.p.wander_period)
        if self._wander_key != period:
            u = np.empty((1, 1))
            fill_uniform(np.int64(self.seed), np.array([self.agent]), np.int64(period), np.int64(S_EXPLORE), u)
            self._wander = bump(float(u[0, 0]) * math.pi, self.p.wander_weight, 2.0)
            self._wander_key = period
        best = _explore_channel(to_allocentric(sonar, heading), self.p.open_range, self._novel, self._wander)
        if best < 0:
            return np.zeros(DIRECTIONS)
        # Expl "to explore unmapped areas": lower where the map knows the way (known_explore 1: x 1.0, exactly)
        return _channel_bump(best, self.p.width) * (
            self.p.known_explore + (1.0 - self.p.known_explore) * self._novel[best]
        )

    def _novelty(self, use_map: bool) -> np.ndarray:
        """Per direction, 1 where no node of the map lies within `novelty_radius`, falling with each one that does."""
        if not (use_map and self.map.nodes):
            return np.ones(DIRECTIONS)
        pos = np.array([n.position for n in self.map.nodes]) - self.xy
        dist = np.hypot(pos[:, 0], pos[:, 1])
        near = (dist < self.p.novelty_radius) & (dist > 0.2)
        if not near.any():
            return np.ones(DIRECTIONS)
        ang = np.arctan2(pos[near, 1], pos[near, 0])
        seen = np.exp(4.0 * (np.cos(ANGLES[:, None] - ang[None, :]) - 1.0)).sum(axis=1)
        return np.exp(-seen / 2.0)

    # ------------------------------------------------------------ state

    def habits(self) -> dict[str, Any]:
        """What steers the animat besides its map: the news count and the novelty profile, which is
        worked out again only when the map changes (from where the animat was then), so it is memory."""
        obs, news, use_map = self._novel_key or (-1, -1, False)
        return {"news": self.news, "novel": self._novel.tolist(), "novel_key": [obs, news, use_map]}

    def take_habits(self, data: dict[str, Any]) -> None:
        self.news = int(data["news"])
        self._novel = np.array(data["novel"], np.float64)
        obs, news, use_map = data["novel_key"]
        self._novel_key = () if obs < 0 else (int(obs), int(news), bool(use_map))

    def to_data(self) -> dict[str, Any]:
        """The map, what its nodes hold and the odometric frame, as plain data (to save and load)."""
        return {"map": topomap_to_data(self.map, lambda sig: np.asarray(sig).tolist()),
                "assoc": {r: w.tolist() for r, w in self.assoc.items()}, "xy": self.xy.tolist(),
                "since": self.since.tolist(), "at": self.at.tolist(), "D": self.D, "created": self.created,
                "born": self.born, "observations": self.observations, "relocalize": self.relocalize,
                "news": self.news}  # fmt: skip

    def from_data(self, data: dict[str, Any]) -> None:
        try:
            self.map = topomap_from_data(data["map"], self.map.signatures, self.map.params, place_from_data,
                                         "a bg map", "BgController.map_data()")  # fmt: skip
            assoc = {r: np.array(data["assoc"].get(r, [0.0] * len(self.map.nodes)), np.float64)
                     for r in self.resources}  # fmt: skip
            if any(w.shape != (len(self.map.nodes),) for w in assoc.values()):
                raise ValueError("one resource weight per node expected")
            self.assoc = assoc
            self.xy, self.since = np.array(data["xy"], np.float64), np.array(data["since"], np.float64)
            self.at = np.array(data.get("at", self.xy - self.since), np.float64)  # a map without it: xy - since
            self.D, self.created = float(data["D"]), int(data["created"])
            self.born, self.observations = [int(b) for b in data["born"]], int(data["observations"])
            self._known_key = ()
            self.relocalize = bool(data.get("relocalize", False))
            self.news = int(data.get("news", 0))
            if len(self.born) != len(self.map.nodes):
                raise ValueError("one birth per node expected")
        except (KeyError, TypeError, ValueError, AttributeError) as e:
            raise ValueError(f"a bg map: malformed ({e}); expected what BgController.map_data() writes") from None


def place_from_data(data: Any) -> np.ndarray:
    a = np.array(data, np.float64)
    if a.shape != (DIRECTIONS + 8,) or not np.isfinite(a).all():
        raise ValueError(f"a place: expected {DIRECTIONS + 8} finite numbers")
    return a
