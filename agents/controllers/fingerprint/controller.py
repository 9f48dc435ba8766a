"""The fingerprint controller: drive, take a fingerprint every `spacing` metres,
map with it (or localize on a map it is given), report its belief.

It sees the panoramic camera, the laser, the odometry and the compass.
Mapping and localization use only those; the position sensor, when the
robot has one, only steers the carrot along a prescribed route, as the
paper's robot was driven along its tour.  Odometry is integrated along the
compass heading into the odometric frame in which nodes and links live.
"""

from __future__ import annotations

import math
from dataclasses import asdict
from typing import Any

import numpy as np

from agents.controllers.fingerprint.align import Matcher
from agents.controllers.fingerprint.features import Fingerprint, fingerprint
from agents.controllers.fingerprint.params import AlignParams, FeatureParams, FingerprintParams
from agents.controllers.fingerprint.signatures import (
    FingerprintSignatures,
    fingerprint_data,
    fingerprint_from_data,
    map_from_data,  # fmt: skip
    map_to_data,
)
from agents.controllers.navigation.gridbelief import GridBelief
from agents.controllers.navigation.mapshare import SharedMap
from agents.controllers.navigation.params import MapParams
from agents.controllers.navigation.topomap import TopoMap


def check_table(table: dict[str, Any] | None) -> None:
    """The whole [fingerprint] table, its [fingerprint.features] and [fingerprint.align] included."""
    table = table or {}
    FingerprintParams.from_table(table)
    FeatureParams.from_table(table.get("features"))
    AlignParams.from_table(table.get("align"))


def _plain(value: Any) -> Any:
    """Arrays inside a snapshot as lists, so that it is JSON- and msgpack-safe."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


class FingerprintController:
    shares = "map"  # it publishes its map to swarm/<run>/map/<agent> and merges the others' (mapshare.py)

    def reset(self, seed: int, agent: int, params: dict[str, Any]) -> None:
        table = params.get("fingerprint") or {}
        self.p = FingerprintParams.from_table(table)
        self.features = FeatureParams.from_table(table.get("features"))
        self.matcher = Matcher(AlignParams.from_table(table.get("align")))
        self.signatures = FingerprintSignatures(self.matcher)
        map_params = MapParams(theta=self.p.theta, keep=self.p.keep, closure=self.p.closure,
                               sharpness=self.p.sharpness)  # fmt: skip
        if self.p.mode == "localize":
            if params.get("topomap") is None:
                raise ValueError(
                    "[fingerprint].mode = 'localize' needs a map: give params['topomap'] "
                    "(swarm experiment fingerprint-localize builds one with a mapping tour first)"
                )
            self.map = map_from_data(params["topomap"], self.signatures, map_params)
            self.map.belief = np.zeros(0)  # global localization: its first fix starts uniform, whatever the map held
            self.grid: GridBelief | None = GridBelief(self.map)
        else:
            self.map = TopoMap(self.signatures, map_params)
            self.grid = None
        if self.p.drive == "route":
            from agents.controllers.carrot.controller import CarrotController

            self.driver = CarrotController()
        else:
            from agents.controllers.wander.controller import WanderController

            self.driver = WanderController()
        self.driver.reset(seed, agent, params)
        self.agent = agent
        self.shared = SharedMap(self.map, agent, fingerprint_data, fingerprint_from_data)
        self.laser_range = float(params["robot"].get("laser_range") or 8.0)
        self.tick = 0
        self.position = np.zeros(2)  # odometric frame
        self.last_position = np.zeros(2)
        self.since = math.inf  # metres since the last fingerprint (inf: take one at once)
        self.current: Fingerprint | None = None
        self.believed, self.matched = -1, -1
        self.belief = np.zeros(0)  # over nodes, localizing: the chosen filter's (mapping, the map holds its own)
        # (tick, believed node, matched node, nodes in the map, node believed by the links-only filter)
        self.log: list[tuple[int, int, int, int, int]] = []

    @property
    def finished(self) -> bool:
        """The route is driven to its end (an explorer never finishes)."""
        return self.p.drive == "route" and bool(self.driver.stopped)

    def step(self, perception: dict[str, np.ndarray]) -> np.ndarray:
        for name in ("camera_rgb", "camera_range", "laser", "odometry", "compass"):
            if name not in perception:
                raise ValueError(f"fingerprint needs the camera, laser, odometry and compass ({name!r} is missing); "
                                 "the scout has them")  # fmt: skip
        wheels = self.driver.step(perception)
        distance = float(perception["odometry"][0])
        heading = float(perception["compass"])
        self.position = self.position + distance * np.array([math.cos(heading), math.sin(heading)])
        self.since += abs(distance)
        if self.since >= self.p.spacing:
            self.since = 0.0
            self._observe(perception)
        self.tick += 1
        return wheels

    def _observe(self, perception: dict[str, np.ndarray]) -> None:
        scan = np.asarray(perception["laser"], np.float64)
        self.current = fingerprint(perception["camera_rgb"], perception["camera_range"], scan,
                                   self.laser_range, self.features)  # fmt: skip
        moved = self.position - self.last_position
        self.last_position = self.position.copy()
        if self.p.mode == "map":
            self.believed = self.map.observe(self.current, self.position, moved)
            self.shared.adopt(self.believed)
            likelihood, by_links = self.map.likelihood, self.believed
        else:
            likelihood, over_links = self.map.localize(self.current, moved)  # both filters run, both are logged
            on_grid = self.grid.update(likelihood, moved)
            self.belief = on_grid if self.p.filter == "grid" else over_links
            by_links, self.believed = int(np.argmax(over_links)), int(np.argmax(self.belief))
        self.matched = int(np.argmax(likelihood)) if len(likelihood) else self.believed
        self.log.append((self.tick, self.believed, self.matched, len(self.map.nodes), by_links))

    def publish(self) -> dict[str, Any] | None:
        """What changed in the map this tick, for the other robots (mapping only)."""
        return self.shared.publish() if self.p.mode == "map" else None

    def receive(self, sender: int, data: Any) -> None:
        """Merge another robot's publication into the map (ValueError if malformed)."""
        self.shared.receive(sender, data)

    def map_data(self) -> dict[str, Any]:
        """The map as plain data (to save, to send, to localize on later): places, links and fingerprints,
        not where the mapping robot believed itself at the end (a robot localizing on it starts knowing
        nothing)."""
        data = map_to_data(self.map)
        data["belief"] = []
        return data

    def summary(self) -> dict[str, Any]:
        return {"map": {"fingerprints": len(self.log), "nodes": self.map.size, "links": len(self.map.links),
                        "loops_closed": self.map.closures, "from_others": self.shared.added,
                        "merged_with_ours": self.shared.merged}}  # fmt: skip

    def snapshot(self) -> dict[str, Any]:
        return {"tick": self.tick, "position": self.position.tolist(), "last_position": self.last_position.tolist(),
                "since": self.since, "map": map_to_data(self.map), "log": [list(r) for r in self.log],
                "driver": _plain(self.driver.snapshot()), "shared": self.shared.to_data(),
                "params": asdict(self.p), "grid": self.grid.to_data() if self.grid is not None else None,
                "belief": np.asarray(self.belief).tolist(), "believed": self.believed,
                "matched": self.matched}  # fmt: skip

    def restore(self, state: dict[str, Any]) -> None:
        self.tick, self.since = int(state["tick"]), float(state["since"])
        self.position, self.last_position = np.array(state["position"]), np.array(state["last_position"])
        self.map = map_from_data(state["map"], self.signatures, self.map.params)
        self.shared = SharedMap(self.map, self.agent, fingerprint_data, fingerprint_from_data)
        self.shared.restore(state["shared"])
        if self.grid is not None:
            self.grid = GridBelief(self.map)
            self.grid.restore(state["grid"])
        self.belief = np.array(state.get("belief", []), np.float64)
        self.believed, self.matched = int(state.get("believed", -1)), int(state.get("matched", -1))
        self.log = [tuple(row) for row in state["log"]]
        self.driver.restore(state["driver"])

    def route(self) -> np.ndarray | None:
        """The route its driver follows (the carrot's), or None when it wanders."""
        route = getattr(self.driver, "route", None)
        return None if route is None else route()

    def record(self) -> dict[str, np.ndarray]:
        out = {k: v for k, v in self.driver.record().items() if k == "path"}
        out["node"] = np.array(self.believed)
        out["matched"] = np.array(self.matched)
        out["nodes"] = np.array(self.map.size)
        out["folded"] = np.array(sorted(self.map.folded), np.int64)
        out["links"] = np.array(list(self.map.links), np.int64).reshape(-1, 2)
        out["belief"] = np.asarray(self.belief if self.p.mode == "localize" else self.map.belief, np.float64)
        if self.current is not None:
            out["fingerprint"] = self.current.codes
        return out
