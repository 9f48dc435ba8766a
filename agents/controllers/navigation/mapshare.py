"""Mapping together: a topological map that robots publish and merge.

Each robot publishes what changed in its map since its last publication:
the nodes it made itself (mean signature, odometric centre, observations,
visits) and every link it knows, each end named by a global id (the robot
that made the node, that robot's node number).  A receiver merges a node it
has not seen by signature match: when the node's mean matches one of its own
nodes with P >= MapParams.merge_match, it is the same place (an alias: one node per place);
else it becomes a new node of the receiver's map.  Links come over through
the aliases; a link the receiver drove itself is kept as it is.  A node the
receiver has made its own since (it observed there) is no longer overwritten
by the sender's later means.

Frames: every robot integrates its odometry along the compass, so link
displacements mean the same for every robot, and two robots' odometric
frames differ by a translation only (where each started).  Each alias (a
sender's node that is one of ours) measures that translation: the receiver
keeps, per sender, the mean of (our centre - theirs) over its aliases and
puts the sender's nodes it copies at their centre plus that offset (until
the first alias, at their centre as sent: right for robots that leave from
one nest).  Nodes are never matched by position; a map that closes loops
only onto nodes near by odometry (the bg animat's) needs the offset.

The data is plain (lists, numbers), as it crosses the wire; the signature is
turned into data and back by the functions the controller gives.  Malformed
data is refused with ValueError, and nothing of it is merged.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from agents.controllers.navigation.topomap import TopoMap

GlobalId = tuple[int, int]  # (robot that made the node, its number there)


class SharedMap:
    def __init__(self, topomap: TopoMap, agent: int, encode: Callable[[Any], Any], decode: Callable[[Any], Any]):
        self.map, self.agent, self.encode, self.decode = topomap, agent, encode, decode
        self.local: dict[GlobalId, int] = {}  # another robot's node -> ours (its copy, or the node it aliases)
        self.origin: dict[int, GlobalId] = {}  # our copies of other robots' nodes -> theirs
        self.adopted: set[int] = set()  # copies we have since observed at: ours now, not overwritten
        self.sent_nodes: dict[
            int, tuple
        ] = {}  # our node -> (observations, visits) last sent (a mean changes with them)
        self.sent_links: dict[tuple[int, int], int] = {}  # link -> count last sent
        self.merged = 0  # other robots' nodes merged into one of ours (same place)
        self.added = 0  # other robots' nodes added as new places
        self.frames: dict[int, tuple[np.ndarray, int]] = {}  # sender -> (mean offset to our frame, aliases behind it)
        self.sent_at: dict[int, np.ndarray] = {}  # our copies -> the centre their maker last sent

    def to_data(self) -> dict[str, Any]:
        """What a resumed robot needs to go on sharing exactly as before (the map itself is saved apart)."""
        return {"local": [[a, n, i] for (a, n), i in self.local.items()],
                "origin": [[i, a, n] for i, (a, n) in self.origin.items()], "adopted": sorted(self.adopted),
                "sent_nodes": [[i, o, v] for i, (o, v) in self.sent_nodes.items()],
                "sent_links": [[a, b, c] for (a, b), c in self.sent_links.items()],
                "merged": self.merged, "added": self.added,
                "frames": [[a, *d.tolist(), n] for a, (d, n) in self.frames.items()],
                "sent_at": [[i, *p.tolist()] for i, p in self.sent_at.items()]}  # fmt: skip

    def restore(self, data: dict[str, Any]) -> None:
        self.local = {(int(a), int(n)): int(i) for a, n, i in data["local"]}
        self.origin = {int(i): (int(a), int(n)) for i, a, n in data["origin"]}
        self.adopted = {int(i) for i in data["adopted"]}
        self.sent_nodes = {int(i): (int(o), int(v)) for i, o, v in data["sent_nodes"]}
        self.sent_links = {(int(a), int(b)): int(c) for a, b, c in data["sent_links"]}
        self.merged, self.added = int(data["merged"]), int(data["added"])
        self.frames = {int(a): (np.array([dx, dy], np.float64), int(n)) for a, dx, dy, n in data.get("frames", [])}
        self.sent_at = {int(i): np.array([x, y], np.float64) for i, x, y in data.get("sent_at", [])}

    def global_id(self, node: int) -> GlobalId:
        return self.origin.get(node, (self.agent, node))

    # ------------------------------------------------------------- publish

    def publish(self) -> dict[str, Any] | None:
        """What changed since the last publication, or None."""
        m, nodes = self.map, []
        for i, node in enumerate(m.nodes):
            if i in self.origin or i in m.folded:  # others' nodes are theirs to send; a folded one is no place
                continue
            stamp = (node.observations, node.visits)
            if self.sent_nodes.get(i) != stamp:
                self.sent_nodes[i] = stamp
                nodes.append([i, self.encode(node.mean), node.position.tolist(), node.observations, node.visits])
        links = []
        for (a, b), link in m.links.items():
            if self.sent_links.get((a, b)) != link.count:
                self.sent_links[(a, b)] = link.count
                links.append([*self.global_id(a), *self.global_id(b), *link.displacement.tolist(), link.count])
        return {"nodes": nodes, "links": links} if nodes or links else None

    # ------------------------------------------------------------- receive

    def receive(self, sender: int, data: Any) -> None:
        """Merge another robot's publication (raises ValueError on malformed data, merging none of it)."""
        if sender == self.agent:
            return
        nodes, links = self._parse(sender, data)
        m = self.map
        for number, mean, position, observations, visits in nodes:
            key = (sender, number)
            if key in self.local:
                i = self.local[key]
                if i in self.origin and i not in self.adopted:  # still only theirs: take their latest
                    node = m.nodes[i]
                    node.mean, node.members = mean, [mean]
                    node.observations, node.visits = observations, visits
                    node.position, self.sent_at[i] = position + self.offset(sender), position
                continue
            same = self._same_place(mean, sender, position + self.offset(sender))
            if same is not None:
                self.local[key] = same
                self.merged += 1
                self._align(sender, m.nodes[same].position - position)
            else:
                i = m.add_node(mean, position + self.offset(sender), observations, visits)
                self.local[key], self.origin[i], self.sent_at[i] = i, key, position
                self.added += 1
        for ga, gb, displacement, count in links:
            a, b = self.ours(ga), self.ours(gb)
            if a is not None and b is not None:
                m.put_link(a, b, displacement, count)

    def offset(self, sender: int) -> np.ndarray:
        """What to add to a centre in `sender`'s odometric frame to have it in ours (0 until an alias tells)."""
        return self.frames[sender][0] if sender in self.frames else np.zeros(2)

    def _align(self, sender: int, sample: np.ndarray) -> None:
        """One more alias measured the offset between the frames: the copies not yet ours move with it."""
        mean, n = self.frames.get(sender, (np.zeros(2), 0))
        self.frames[sender] = (mean + (sample - mean) / (n + 1), n + 1)
        shift = self.frames[sender][0]
        for i, (a, _) in self.origin.items():
            if a == sender and i not in self.adopted:
                self.map.nodes[i].position = self.sent_at[i] + shift

    def adopt(self, node: int) -> None:
        """This robot observed at `node`: if it was a copy, it is ours now."""
        if node in self.origin:
            self.adopted.add(node)

    def ours(self, g: GlobalId) -> int | None:
        """Our node for a global id (ours, a copy of it, or the node it aliases); None if we have none."""
        if g[0] == self.agent:
            return g[1] if 0 <= g[1] < len(self.map.nodes) and g[1] not in self.origin else None
        return self.local.get(g)

    def _same_place(self, mean: Any, sender: int, position: np.ndarray) -> int | None:
        """Our node that `mean` matches best, if at least MapParams.merge_match (a
        merge is a loop closed across robots, with no odometry to back it, so
        it asks more than a closure), leaving out the sender's own other nodes
        (it already told them apart); with MapParams.closure_radius, only nodes
        that near `position` (the sender's centre in our frame)."""
        m = self.map
        if not m.nodes:
            return None
        candidates = [i for i in range(len(m.nodes)) if self.origin.get(i, (None,))[0] != sender]
        if m.params.closure_radius is not None:  # a map that closes loops only near by odometry merges so too
            near = m.params.closure_radius
            candidates = [i for i in candidates if np.hypot(*(m.nodes[i].position - position)) <= near]
        if not candidates:
            return None
        likelihood = m.signatures.likelihoods(mean, [m.nodes[i].mean for i in candidates])
        best = int(np.argmax(likelihood))
        return candidates[best] if likelihood[best] >= m.params.merge_match else None

    def _parse(self, sender: int, data: Any) -> tuple[list, list]:
        try:
            nodes = [(int(n), self.decode(mean), np.array(pos, np.float64).reshape(2), int(obs), int(visits))
                     for n, mean, pos, obs, visits in data["nodes"]]  # fmt: skip
            links = [((int(a0), int(a1)), (int(b0), int(b1)), np.array([dx, dy], np.float64), int(count))
                     for a0, a1, b0, b1, dx, dy, count in data["links"]]  # fmt: skip
        except (KeyError, TypeError, ValueError, IndexError) as e:
            raise ValueError(f"a map from agent {sender}: malformed ({type(e).__name__}: {e})") from None
        finite = all(np.isfinite(p).all() for _, _, p, _, _ in nodes) and all(
            np.isfinite(d).all() for *_, d, _ in links
        )
        if not finite or any(n < 0 or o < 1 or v < 1 for n, _, _, o, v in nodes):
            raise ValueError(f"a map from agent {sender}: malformed (a number out of range)")
        return nodes, links
