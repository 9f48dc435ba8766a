"""A colony's shared map: the animat's places and what they hold, over the
`map` key space (swarm/<run>/map/<agent>).

The places and links go as the fingerprint robots send theirs
(agents/controllers/navigation/mapshare.py: aliases by signature, copies
for new places, frames aligned by the aliases).  On top, each publication
carries `holds`: the resource weights (DA, Ep, E) of every node whose
weights moved by `HOLDS_STEP` or more since they were last sent or heard,
each node named by its global id.  A receiver takes them as they come: the
latest news of a place wins, whoever brings it (an animat that finds a
resource gone there makes the others forget it too; one that finds it
again makes them learn it).  What it heard counts as sent, so news is
never echoed back.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from agents.controllers.bg.places import Navigator, place_from_data
from agents.controllers.navigation.mapshare import SharedMap

HOLDS_STEP = 0.1  # a node's weights are sent again once one of them moved this much


class ColonyMap:
    def __init__(self, nav: Navigator, agent: int):
        self.nav, self.agent = nav, agent
        self.shared = SharedMap(nav.map, agent, lambda sig: np.asarray(sig).tolist(), place_from_data)
        # per node, the weights last sent or heard (NaN: none yet), the resources in the navigator's order
        self.sent = np.full((0, len(nav.resources)), np.nan)
        self.heard = 0  # weights of a place taken from another animat

    def _sent_rows(self) -> np.ndarray:
        """`sent`, one row per node of the map (nodes made since start with none)."""
        grow = len(self.nav.map.nodes) - len(self.sent)
        if grow > 0:
            self.sent = np.vstack([self.sent, np.full((grow, self.sent.shape[1]), np.nan)])
        return self.sent

    def publish(self) -> dict[str, Any] | None:
        """What changed since the last publication: places, links and what places hold; None if nothing."""
        data = self.shared.publish() or {"nodes": [], "links": []}
        weights = np.stack([self.nav.assoc[r] for r in self.nav.resources], axis=1)
        last = self._sent_rows()
        # a node never sent counts from 0: it goes once it holds something (weights are >= 0)
        moved = np.abs(weights - np.nan_to_num(last)).max(axis=1, initial=0.0) >= HOLDS_STEP
        moved[list(self.nav.map.folded)] = False
        holds = []
        for i in np.flatnonzero(moved):
            last[i] = weights[i]
            holds.append([*self.shared.global_id(int(i)), *np.round(weights[i], 4).tolist()])
        if holds:
            data["holds"] = holds
        return data if data["nodes"] or data["links"] or holds else None

    def receive(self, sender: int, data: Any) -> None:
        """Merge another animat's publication (ValueError on malformed data, merging none of it)."""
        holds = self._parse_holds(sender, data)
        self.shared.receive(sender, data)
        self.nav.grow()
        for a, n, w in holds:
            i = self.shared.ours((a, n))
            if i is None or i in self.nav.map.folded:
                continue
            for r, value in zip(self.nav.resources, w, strict=True):
                self.nav.assoc[r][i] = value
            self._sent_rows()[i] = w
            self.heard += 1

    def adopt(self, node: int) -> None:
        self.shared.adopt(node)

    def _parse_holds(self, sender: int, data: Any) -> list[tuple[int, int, np.ndarray]]:
        if not isinstance(data, dict):
            raise ValueError(f"a map from agent {sender}: malformed (expected a table)")
        k = len(self.nav.resources)
        try:
            holds = [(int(row[0]), int(row[1]), np.array(row[2:], np.float64)) for row in data.get("holds", [])]
        except (TypeError, ValueError, IndexError) as e:
            raise ValueError(f"a map from agent {sender}: malformed holds ({type(e).__name__}: {e})") from None
        if any(w.shape != (k,) or not np.isfinite(w).all() or (w < 0).any() or (w > 1).any() for *_, w in holds):
            raise ValueError(f"a map from agent {sender}: malformed holds (expected {k} weights in [0, 1] a node)")
        return holds

    def to_data(self) -> dict[str, Any]:
        rows = [[int(i), *self.sent[i].tolist()] for i in np.flatnonzero(~np.isnan(self.sent[:, 0]))]
        return {"shared": self.shared.to_data(), "sent": rows, "heard": self.heard}

    def restore(self, data: dict[str, Any]) -> None:
        self.shared.restore(data["shared"])
        self.sent = np.full((len(self.nav.map.nodes), self.sent.shape[1]), np.nan)
        for row in data["sent"]:
            self.sent[int(row[0])] = row[1:]
        self.heard = int(data["heard"])
