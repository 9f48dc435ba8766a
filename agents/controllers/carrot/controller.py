"""The carrot controller: plan once with A*, then follow the carrot.

The plan starts where the position sensor first says the robot is (with its
noise), on the occupancy grid of the map the robot is given (1 cm cells, 4 cm
clearance by default), to the goal or through the waypoints of a route.  The
robot stops once its sensor puts it within `arrive` of the last point.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from agents.controllers.navigation.astar import Planner
from agents.controllers.navigation.follow import CarrotFollower, PaperCarrotFollower
from swarm.core.params import OURS, PAPER, declared
from swarm.core.tables import params_from_table


@dataclass(frozen=True)
class CarrotParams:
    """Follow the carrot, the DFT paper's baseline (Appendix B; docs/arena.md, the carrot controller)."""

    cell: float = declared(
        0.01, source=PAPER, where="Appendix B: A* over an eight neighbor grid with a cell size of 1 cm"
    )
    clearance: float = declared(0.04, source=PAPER, where="Appendix B: a minimum obstacle distance of 4 cm")
    k_fic: float = declared(
        3.0,
        source=OURS,
        reason=(
            "steering gain, 1/s: Appendix B's phi_fic = k_fic (phi_c - phi_h) gives no value; phi is "
            "our turn rate (docs/arena.md)"
        ),
    )
    k_look: float = declared(
        0.01, source=PAPER, where="Appendix B, eq. 18: the look ahead point at distance k_look = 1 cm"
    )
    speed: float = declared(
        0.05,
        source=OURS,
        reason="cruise speed, m/s, not given: about the DFT robot's straight-ahead 5.5 cm/s (docs/arena.md)",
    )
    window: int = declared(
        40,
        source=OURS,
        reason=(
            "variant 'ours': path points searched ahead of the last carrot: never back, never across a fold of "
            "the path (docs/arena.md)"
        ),
    )
    variant: str = declared(
        "ours",
        source=OURS,
        reason=(
            "which follow the carrot: 'ours' (the windowed carrot above, turning on the spot) or 'paper' "
            "(Appendix B literally: eq. 18's carrot, the nearest point of the whole path, so it may jump across "
            "a fold and cut corners; the robot drives at `speed` while it steers, its turn rate clipped to what "
            "the wheels allow at that speed: Appendix B gives a steering angle and no speed law, and a steering "
            "angle is a car's, which cannot turn on the spot; `window` is unused) (docs/arena.md)"
        ),
    )
    arrive: float = declared(
        0.02,
        source=OURS,
        reason=(
            "stop within this distance of the end by the sensor; the paper's goal test is the "
            "supervisor's (docs/arena.md)"
        ),
    )

    @classmethod
    def from_table(cls, table: dict[str, Any] | None) -> CarrotParams:
        p = params_from_table(cls, table, "carrot", ints=("window",), texts=("variant",))
        if p.variant not in VARIANTS:
            raise ValueError(f"[carrot]: variant is 'ours' or 'paper', not {p.variant!r}")
        return p


VARIANTS = {"ours": CarrotFollower, "paper": PaperCarrotFollower}


class CarrotController:
    def reset(self, seed: int, agent: int, params: dict[str, Any]) -> None:
        self.agent = agent
        self.p = CarrotParams.from_table(params.get("carrot"))
        robot = params["robot"]
        self.axle, self.max_wheel = float(robot["axle"]), float(robot["max_wheel_speed"])
        m = params["map"]
        self.planner = Planner(tuple(m["size"]), np.asarray(m["rects"], np.float64),
                               np.asarray(m["segments"], np.float64), self.p.cell, self.p.clearance)  # fmt: skip
        route = params.get("route")
        goal = params.get("goal")
        self.targets = [tuple(w) for w in route] if route else ([tuple(goal)] if goal is not None else [])
        self.follower: CarrotFollower | None = None
        self.planned = False
        self.stopped = not self.targets
        self.no_path = False

    def _plan(self, x: float, y: float) -> None:
        legs, here = [], (x, y)
        for target in self.targets:
            length, points = self.planner.plan(here, target)
            if not math.isfinite(length):
                self.no_path, self.stopped = True, True
                return
            legs.append(points)
            here = target
        path = np.concatenate(legs) if legs else np.zeros((1, 2))
        self.follower = self._follower(path)

    def _follower(self, path: np.ndarray) -> CarrotFollower:
        p = self.p
        return VARIANTS[p.variant](path, p.k_fic, p.k_look, p.speed, p.window)

    def step(self, perception: dict[str, np.ndarray]) -> np.ndarray:
        if "position" not in perception or "compass" not in perception:
            raise ValueError("carrot needs the position and compass sensors (the epuck has them)")
        x, y = (float(v) for v in perception["position"])
        heading = float(perception["compass"])
        if not self.planned:
            self.planned = True
            if not self.stopped:
                self._plan(x, y)
        if self.stopped or self.follower is None:
            return np.zeros(2)
        end = self.follower.path[-1]
        if self.follower.at_end and math.hypot(end[0] - x, end[1] - y) < self.p.arrive:
            self.stopped = True
            return np.zeros(2)
        left, right = self.follower.wheels(x, y, heading, self.axle, self.max_wheel)
        return np.array([left, right])

    def snapshot(self) -> dict[str, Any]:
        f = self.follower
        return {"planned": self.planned, "stopped": self.stopped, "no_path": self.no_path,
                "path": None if f is None else f.path.copy(), "index": 0 if f is None else f.index,
                "params": asdict(self.p)}  # fmt: skip

    def restore(self, state: dict[str, Any]) -> None:
        self.planned, self.stopped, self.no_path = state["planned"], state["stopped"], state["no_path"]
        self.follower = None
        if state["path"] is not None:
            self.follower = self._follower(np.asarray(state["path"]))
            self.follower.index = int(state["index"])

    def route(self) -> np.ndarray | None:
        """The path it follows (metres), or None before it has one."""
        return None if self.follower is None else self.follower.path

    def record(self) -> dict[str, np.ndarray]:
        f = self.follower
        if f is None:
            return {"path": np.zeros((0, 2))}
        return {"path": f.path, "carrot": f.path[f.index]}
