"""Topological maps in an arena recording: the nodes and links of every
controller that keeps a map (its `record()` gives `node`, `nodes`, `links`,
and may give `belief`, `fingerprint` and `holds`, the resources each node
holds), over the floor plan.

A node is drawn where the robot truly was, on average, while that node was
its current one: ground truth for display only (the controller knows only
its odometry).  In process the recorder asks the controllers; in a
distributed run the world reads the robots' publications (PublishedMaps).

    world/map/<agent>/nodes   points, one per node, labelled n<k>
    world/map/<agent>/links   line strips between linked nodes
    world/map/<agent>/here    the current node
    map/<agent>               the same as rerun graph nodes and edges (a graph view)
    map/<agent>/belief        the belief over nodes, a bar chart
    map/<agent>/fingerprint   the current fingerprint of a place, as text
"""

from __future__ import annotations

import numpy as np


def flip(xy: np.ndarray) -> np.ndarray:
    out = np.array(xy, np.float32).reshape(-1, 2)
    out[:, 1] *= -1
    return out


class PublishedMaps:
    """Distributed runs: the world sees each robot's map only as its publications
    (agents.controllers.navigation.mapshare).  From them it keeps what MapLog
    draws: the robot's own nodes, its links between them, and as the current
    node the one whose observations grew this tick (where the fingerprint was
    taken).  Links to other robots' nodes are not drawn."""

    def __init__(self) -> None:
        self.observations: dict[int, dict[int, int]] = {}
        self.links: dict[int, set[tuple[int, int]]] = {}
        self.current: dict[int, int] = {}

    def update(self, agent: int, data) -> dict | None:
        """The record() MapLog needs, or None for a publication it cannot read."""
        try:
            seen = self.observations.setdefault(agent, {})
            grown = [(int(obs) - seen.get(int(n), 0), int(n)) for n, _, _, obs, _ in data["nodes"]]
            for n, _, _, obs, _ in data["nodes"]:
                seen[int(n)] = int(obs)
            links = self.links.setdefault(agent, set())
            for a0, a1, b0, b1, *_ in data["links"]:
                if int(a0) == int(b0) == agent:
                    links.add((int(a1), int(b1)))
        except (KeyError, TypeError, ValueError):
            return None
        if grown:
            self.current[agent] = max(grown)[1]
        if agent not in self.current:
            return None
        return {"node": self.current[agent], "nodes": len(seen), "links": np.array(sorted(links)).reshape(-1, 2)}


class MapLog:
    def __init__(self, rr, rec, colours: np.ndarray):
        self.rr, self.rec, self.colours = rr, rec, colours
        self.sums: dict[int, dict[int, np.ndarray]] = {}
        self.shown: dict[int, tuple] = {}

    def flush(self) -> None:
        """Every map is logged as it changes: nothing waits for a flush."""

    def capture(self, tick: int, agent: int, record: dict, xy: np.ndarray) -> None:
        node = int(record.get("node", -1))
        if node < 0:
            return
        sums = self.sums.setdefault(agent, {})
        s = sums.setdefault(node, np.zeros(3))
        s += (xy[0], xy[1], 1.0)
        links = np.asarray(record.get("links", np.zeros((0, 2))), np.int64).reshape(-1, 2)
        key = (int(record.get("nodes", 0)), len(links), node)
        if self.shown.get(agent) == key:
            return
        self.shown[agent] = key
        self._log(tick, agent, node, links, record)

    def _log(self, tick: int, agent: int, node: int, links: np.ndarray, record: dict) -> None:
        rr, rec = self.rr, self.rec
        rec.set_time("tick", sequence=tick)
        sums = self.sums[agent]
        folded = set(np.asarray(record.get("folded", []), np.int64).tolist())
        ids = [k for k in sorted(sums) if k not in folded]
        where = {k: sums[k][:2] / sums[k][2] for k in ids}
        colour = self.colours[agent] if agent < len(self.colours) else (200, 200, 200)
        pts = flip(np.array([where[k] for k in ids]))
        holds = list(record.get("holds", []))  # what each node holds (the bg animat's resources), if anything
        labels = [f"n{k} {holds[k]}".strip() if k < len(holds) else f"n{k}" for k in ids]
        rec.log(f"world/map/{agent}/nodes", rr.Points2D(pts, radii=0.12, colors=[colour], labels=labels,
                                                        draw_order=6.0))  # fmt: skip
        shown = [(a, b) for a, b in links.tolist() if a in ids and b in ids]
        strips = [flip(np.array([where[a], where[b]])) for a, b in shown]
        rec.log(
            f"world/map/{agent}/links", rr.LineStrips2D(strips, colors=[(60, 110, 220)], radii=0.03, draw_order=5.5)
        )
        rec.log(f"world/map/{agent}/here", rr.Points2D(flip(where[node]), radii=0.25, colors=[(230, 40, 40)],
                                                       draw_order=6.5))  # fmt: skip
        rec.log(f"map/{agent}", rr.GraphNodes([f"n{k}" for k in ids], positions=pts, labels=[f"n{k}" for k in ids]),
                rr.GraphEdges([(f"n{a}", f"n{b}") for a, b in shown], graph_type="undirected"))  # fmt: skip
        belief = np.asarray(record.get("belief", np.zeros(0)), np.float64)
        if len(belief):
            rec.log(f"map/{agent}/belief", rr.BarChart(belief))
        if "fingerprint" in record:
            from agents.controllers.fingerprint.align import to_string

            rec.log(f"map/{agent}/fingerprint", rr.TextDocument(to_string(np.asarray(record["fingerprint"]))))

    @staticmethod
    def views(rrb, agent: int, name: str) -> list:
        """The viewer's panels for one robot's map: its graph and its belief over the nodes."""
        return [rrb.GraphView(origin=f"/map/{agent}", name=f"{name} {agent} map"),
                rrb.BarChartView(origin=f"/map/{agent}/belief", name=f"{name} {agent} belief")]  # fmt: skip
