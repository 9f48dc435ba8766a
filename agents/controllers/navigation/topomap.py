"""A topological map with Markov localization over its nodes, generic over what
a place looks like (its signature).

The fingerprint controller plugs in fingerprints of places (Tapus et al.
2006); the BG animat will plug in its grey-level panorama and sonar (Girard et
al. 2005, after Filliat).  A `Signatures` model says how likely an
observation is at each node and what the mean of a node's observations is;
everything else is here:

- nodes: a mean signature, the observations that made it (the last
  `keep`), where it lies in the robot's odometric frame (the mean of its
  observations' positions: for links and display, never for matching), and
  how many observations a visit to it lasts;
- links: between nodes visited one after the other, with the odometric
  displacement from the first node's centre (as it was when the robot
  left it) to the second's (as it was when the robot came in; a new node's
  centre is then its first observation), averaged over the traversals;
  a new node is linked, too, to the nodes observed within `near` of where
  it starts in the last `recent` metres of travel (the corridor stretch
  before a room's door and the one after it meet there, though the robot
  went through the room in between);
- mapping (the paper's steps 1-5): each observation joins the current node
  when its dissimilarity (1 - P(match)) to the node's mean is below theta;
  else, if the belief given that the robot has left the current node puts
  at least `closure` on one known node and the observation matches that
  node with P >= `closure_match` (stricter than joining: a wrong loop bends
  the map's topology, a missed one only adds a node), the robot is there
  again (a loop closed: link to it and go on there); else it starts a new node;
- late closing: while a node is young (its first `young` observations), an
  observation that matches a known node that well, and about as well as the
  young one, folds the young node into it (its observations and links go
  there, it stands for no place any more): the robot came back to a place
  whose first view on entering did not match, as a door's view seldom does;
- Markov (POMDP) localization: a belief over nodes, predicted with the
  odometry since the last observation (stay for as long as visits there
  last, or move along a link whose direction agrees with the motion), then
  corrected by the likelihood of the observation at every node;
- shortest routes between nodes over the links (Dijkstra).
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from agents.controllers.navigation.params import MapParams


class Signatures(Protocol):
    """What a place looks like, to the map."""

    def likelihoods(self, observation: Any, means: list[Any]) -> np.ndarray:
        """P(observation | node) for every node's mean signature (each in [0, 1])."""
        ...

    def mean(self, members: list[Any]) -> Any:
        """The signature that stands for a node's observations."""
        ...


@dataclass
class Node:
    mean: Any
    members: list[Any]
    position: np.ndarray  # mean odometric position of the observations (x, y)
    observations: int = 1
    visits: int = 1
    seen_at: list[tuple[float, float, float]] = field(default_factory=list)  # (x, y, odometer) of each observation

    @property
    def dwell(self) -> float:
        """Observations a visit lasts, on average."""
        return self.observations / max(self.visits, 1)


@dataclass
class Link:
    displacement: np.ndarray  # from the first node's centre to the second's, odometric frame
    count: int = 1

    @property
    def distance(self) -> float:
        return float(np.hypot(*self.displacement))

    @property
    def direction(self) -> float:
        return float(math.atan2(self.displacement[1], self.displacement[0]))


@dataclass
class TopoMap:
    signatures: Signatures
    params: MapParams = field(default_factory=MapParams)
    nodes: list[Node] = field(default_factory=list)
    links: dict[tuple[int, int], Link] = field(default_factory=dict)
    current: int = -1
    belief: np.ndarray = field(default_factory=lambda: np.zeros(0))
    closures: int = 0
    likelihood: np.ndarray = field(default_factory=lambda: np.zeros(0))  # of the last observation
    odometer: float = 0.0  # distance travelled, for `recent`
    folded: dict[int, int] = field(default_factory=dict)  # young nodes found to be a known one: node -> that one
    # per node: (observations of `seen_at` read, the largest odometer among them); see _last_seen
    _latest: list[tuple[int, float]] = field(default_factory=list, repr=False, compare=False)

    @property
    def size(self) -> int:
        """Nodes that stand for a place (folded ones do not)."""
        return len(self.nodes) - len(self.folded)

    def resolve(self, node: int) -> int:
        """The node a (possibly folded) node stands for."""
        while node in self.folded:
            node = self.folded[node]
        return node

    def _likelihoods(self, observation: Any) -> np.ndarray:
        likelihood = self.signatures.likelihoods(observation, self.means())
        if self.folded:
            likelihood[list(self.folded)] = 0.0  # a folded node is never where the robot is
        return likelihood

    # -------------------------------------------------------------- queries

    def means(self) -> list[Any]:
        return [n.mean for n in self.nodes]

    def neighbours(self, i: int) -> list[tuple[int, Link]]:
        out = []
        for (a, b), link in self.links.items():
            if a == i:
                out.append((b, link))
            elif b == i:
                out.append((a, Link(-link.displacement, link.count)))
        return out

    def route(self, start: int, goal: int) -> list[int]:
        """Nodes of a shortest route (by link distance) from start to goal; [] if none."""
        dist, back = {start: 0.0}, {}
        heap = [(0.0, start)]
        while heap:
            d, i = heapq.heappop(heap)
            if i == goal:
                path = [goal]
                while path[-1] != start:
                    path.append(back[path[-1]])
                return path[::-1]
            if d > dist.get(i, math.inf):
                continue
            for j, link in self.neighbours(i):
                nd = d + link.distance
                if nd < dist.get(j, math.inf):
                    dist[j], back[j] = nd, i
                    heapq.heappush(heap, (nd, j))
        return []

    # ------------------------------------------------------- localization

    def _edges(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(from, to, direction) of every link both ways, cached until the links change."""
        key = (len(self.nodes), len(self.links), sum(link.count for link in self.links.values()))
        if getattr(self, "_edge_key", None) != key:
            ab = np.array(list(self.links), np.int64).reshape(-1, 2)
            d = np.array([link.direction for link in self.links.values()], np.float64)
            self._edge_cache = (np.concatenate((ab[:, 0], ab[:, 1])), np.concatenate((ab[:, 1], ab[:, 0])),
                                np.concatenate((d, (d + 2 * math.pi) % (2 * math.pi) - math.pi)))  # fmt: skip
            self._edge_key = key
        return self._edge_cache

    def predict(self, displacement: np.ndarray) -> np.ndarray:
        """The belief after the robot moved `displacement` (odometric frame)."""
        k = len(self.nodes)
        if k == 0:
            return self.belief
        b = self.belief
        moved = float(np.hypot(*displacement))
        src, dst, direction = self._edges()
        dwell = np.array([n.dwell for n in self.nodes])
        leave = 1.0 / np.maximum(dwell, 1.0) if moved > 0 else np.zeros(k)
        leave = np.where(np.bincount(src, minlength=k) > 0, leave, 0.0)  # a node without links keeps its belief
        heading = math.atan2(displacement[1], displacement[0])
        w = np.exp(self.params.kappa * (np.cos(heading - direction) - 1.0))
        w = w / np.bincount(src, weights=w, minlength=k)[src]
        out = b * (1.0 - leave) + np.bincount(dst, weights=b[src] * leave[src] * w, minlength=k)
        out = (1.0 - self.params.spread) * out + self.params.spread / k
        return out / out.sum()

    def correct(self, prior: np.ndarray, likelihood: np.ndarray) -> np.ndarray:
        """The belief after an observation.  With `sharpness` above 1 a view that matches one node
        clearly better than another moves the belief more: a signature model whose P(match) is
        flat between places that look somewhat alike (a fingerprint's logistic) lets a belief left
        on the wrong one come back in fewer observations."""
        weight = likelihood if self.params.sharpness == 1.0 else likelihood**self.params.sharpness
        post = prior * (weight + self.params.floor)
        total = post.sum()
        return post / total if total > 0 else np.full(len(prior), 1.0 / len(prior))

    def localize(self, observation: Any, displacement: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(likelihood, belief) of every node for an observation made after
        moving `displacement`: updates the belief, leaves the map unchanged."""
        likelihood = self._likelihoods(observation) if self.nodes else np.zeros(0)
        self.likelihood = likelihood
        if len(self.belief) == 0:  # first fix: start from the matching alone
            self.belief = np.full(len(self.nodes), 1.0 / max(len(self.nodes), 1))
        self._grow_belief()
        self.belief = self.correct(self.predict(displacement), likelihood) if self.nodes else self.belief
        return likelihood, self.belief

    # ------------------------------------------------------------ mapping

    def observe(self, observation: Any, position: np.ndarray, displacement: np.ndarray,
                extent: float | None = None) -> int:  # fmt: skip
        """Map one observation made at odometric `position` after moving
        `displacement`: join the current node, close a loop to a known one, or
        start a new node (steps 1-5 of the paper).  With `extent`, the current
        node is joined only within that distance of where it was first seen (a dense map:
        where places look alike, a corridor still becomes a chain of nodes).
        Returns the node it joined."""
        position = np.asarray(position, np.float64)
        self.odometer += float(np.hypot(*displacement))
        if not self.nodes:
            self.likelihood = np.ones(1)
            return self._new_node(observation, position)
        likelihood = self._likelihoods(observation)
        self.likelihood = likelihood
        if len(self.belief) == 0:
            self.belief = np.eye(len(self.nodes))[self.current]
        self._grow_belief()
        self.belief = self.correct(self.predict(displacement), likelihood)
        young = self.nodes[self.current]
        if young.visits == 1 and young.observations <= self.params.young and len(self.nodes) > 1:
            others = likelihood.copy()
            others[self.current] = -1.0
            others[~self._within_reach(position)] = -1.0
            known = int(np.argmax(others))
            if others[known] >= self.params.closure_match and others[known] >= likelihood[self.current] - 0.05:
                self.closures += 1  # the node just started is a place known before: a loop closed late
                self._fold(self.current, known, observation, position)
                return known
        first = self.nodes[self.current].seen_at[0] if self.nodes[self.current].seen_at else None
        near = extent is None or first is None or math.hypot(position[0] - first[0], position[1] - first[1]) <= extent
        if 1.0 - likelihood[self.current] < self.params.theta and near:
            self._join(self.current, observation, position)
            return self.current
        others = self.belief.copy()  # the belief given that the robot has left the current node
        others[self.current] = 0.0
        others[~self._within_reach(position)] = 0.0
        best = int(np.argmax(others))
        share = others[best] / others.sum() if others.sum() > 0 else 0.0
        if share >= self.params.closure and likelihood[best] >= self.params.closure_match:
            self.closures += 1
            self._move(best, observation, position)
            return best
        return self._new_node(observation, position)

    def _within_reach(self, position: np.ndarray) -> np.ndarray:
        """Which nodes a loop may close onto from `position`: all, or those within `closure_radius` by odometry."""
        if self.params.closure_radius is None:
            return np.ones(len(self.nodes), np.bool_)
        centres = np.array([n.position for n in self.nodes])
        return np.hypot(*(centres - position).T) <= self.params.closure_radius

    # ------------------------------------------------- maps of other robots

    def _grow_belief(self) -> None:
        """Nodes added since the belief was last updated start with none of it."""
        if 0 < len(self.belief) < len(self.nodes):
            self.belief = np.concatenate((self.belief, np.zeros(len(self.nodes) - len(self.belief))))

    def add_node(self, mean: Any, position: np.ndarray, observations: int = 1, visits: int = 1) -> int:
        """A node learned from elsewhere (another robot's map): no observation of
        this robot's yet, so it is never linked by nearness."""
        self.nodes.append(Node(mean, [mean], np.asarray(position, np.float64).copy(), observations, visits))
        self._grow_belief()
        return len(self.nodes) - 1

    def put_link(self, a: int, b: int, displacement: np.ndarray, count: int = 1) -> bool:
        """A link learned from elsewhere; one this robot drove itself is kept.  True if new."""
        key, sign = ((a, b), 1.0) if a < b else ((b, a), -1.0)
        if a == b or key in self.links:
            return False
        self.links[key] = Link(sign * np.asarray(displacement, np.float64), count)
        return True

    def _join(self, i: int, observation: Any, position: np.ndarray) -> None:
        node = self.nodes[i]
        node.members = [*node.members, observation][-self.params.keep :]
        node.position = node.position + (position - node.position) / (node.observations + 1)
        node.observations += 1
        node.seen_at.append((float(position[0]), float(position[1]), self.odometer))
        node.mean = self.signatures.mean(node.members)

    def _link(self, a: int, b: int) -> None:
        key, sign = ((a, b), 1.0) if a < b else ((b, a), -1.0)
        d = sign * (self.nodes[b].position - self.nodes[a].position)
        if key in self.links:
            link = self.links[key]
            link.displacement = link.displacement + (d - link.displacement) / (link.count + 1)
            link.count += 1
        else:
            self.links[key] = Link(d)

    def _fold(self, young: int, known: int, observation: Any, position: np.ndarray) -> None:
        """The young node is the known one: its observations and links go there, and it is no place any more."""
        y, k = self.nodes[young], self.nodes[known]
        self.folded[young] = known
        k.members = [*k.members, *y.members][-self.params.keep :]
        k.position = k.position + (y.position - k.position) * y.observations / (k.observations + y.observations)
        k.observations += y.observations
        k.seen_at += y.seen_at
        k.visits += 1
        for (a, b), link in list(self.links.items()):
            if young in (a, b):
                del self.links[(a, b)]
                other = b if a == young else a
                if other == known:
                    continue
                if (min(other, known), max(other, known)) in self.links:
                    self._link(other, known)  # driven once more
                else:
                    self.put_link(other, known, link.displacement if a == other else -link.displacement)
        self.belief = np.eye(len(self.nodes))[known]
        self.current = known
        self._join(known, observation, position)
        self._edge_key = None

    def _move(self, i: int, observation: Any, position: np.ndarray) -> None:
        self._join(i, observation, position)
        self.nodes[i].visits += 1
        self._link(self.current, i)
        self.current = i
        self.belief = np.eye(len(self.nodes))[i]

    def _last_seen(self, j: int) -> float:
        """The largest odometer node j was observed at (-inf if never).  A node's `seen_at` only grows
        (joins and folds append to it), so only what was appended since the last call is read: over a
        long life a new node would otherwise convert every observation the map ever made."""
        seen = self.nodes[j].seen_at
        while len(self._latest) <= j:
            self._latest.append((0, -math.inf))
        count, latest = self._latest[j]
        if count > len(seen):  # replaced by a shorter record: read it whole
            count, latest = 0, -math.inf
        for entry in seen[count:]:
            latest = max(latest, entry[2])
        self._latest[j] = (len(seen), latest)
        return latest

    def _new_node(self, observation: Any, position: np.ndarray) -> int:
        here = (float(position[0]), float(position[1]), self.odometer)
        self.nodes.append(Node(observation, [observation], position.copy(), seen_at=[here]))
        i = len(self.nodes) - 1
        if self.current >= 0:
            self._link(self.current, i)
        horizon = self.odometer - self.params.recent
        for j, node in enumerate(self.nodes[:-1]):
            if j == self.current or self._last_seen(j) < horizon:
                continue  # not observed within the last `recent` metres: no link by nearness
            seen = np.asarray(node.seen_at).reshape(-1, 3)
            seen = seen[seen[:, 2] >= horizon]
            if np.hypot(*(seen[:, :2] - position).T).min() <= self.params.near:
                self._link(j, i)
        self.current = i
        self.belief = np.eye(len(self.nodes))[i]
        return i


def topomap_to_data(m: TopoMap, encode: Callable[[Any], Any]) -> dict[str, Any]:
    """A map as plain data (msgpack- and JSON-safe); `encode` writes one signature."""
    return {
        "nodes": [{"mean": encode(n.mean), "members": [encode(f) for f in n.members],
                   "position": n.position.tolist(), "observations": n.observations, "visits": n.visits,
                   "seen_at": [list(p) for p in n.seen_at]}
                  for n in m.nodes],
        "links": [[a, b, link.displacement.tolist(), link.count] for (a, b), link in m.links.items()],
        "current": m.current, "belief": np.asarray(m.belief).tolist(), "closures": m.closures,
        "odometer": m.odometer, "folded": [[a, b] for a, b in m.folded.items()],
    }  # fmt: skip


def topomap_from_data(data: dict[str, Any], signatures: Signatures, params: MapParams,
                      decode: Callable[[Any], Any], what: str, writer: str) -> TopoMap:  # fmt: skip
    """The map `topomap_to_data` wrote; ValueError naming `what` and its `writer` if malformed
    (`decode` reads one signature and raises ValueError on a bad one)."""
    try:
        nodes = [Node(decode(n["mean"]), [decode(f) for f in n["members"]], np.array(n["position"], np.float64),
                      int(n["observations"]), int(n["visits"]),
                      [(float(x), float(y), float(o)) for x, y, o in n.get("seen_at", [])])
                 for n in data["nodes"]]  # fmt: skip
        links = {(int(a), int(b)): Link(np.array(d, np.float64), int(c)) for a, b, d, c in data["links"]}
        return TopoMap(signatures, params, nodes, links, int(data.get("current", -1)),
                       np.array(data.get("belief", []), np.float64), int(data.get("closures", 0)),
                       odometer=float(data.get("odometer", 0.0)),
                       folded={int(a): int(b) for a, b in data.get("folded", [])})  # fmt: skip
    except (KeyError, TypeError, ValueError, IndexError) as e:
        raise ValueError(f"{what}: malformed ({type(e).__name__}: {e}); expected what {writer} writes") from None
