"""The dft controller: simultaneous planning and action with dynamic neural fields.

Each tick the robot's sensors write the input layers (goal, the map it is
given as context, its noisy position every `position_every` ticks, its
heading, its proximity sensors), the engine steps every field once, and the
action fields give the wheel speeds.  Planning and acting are the same
dynamics: activity spreads back from the goal through M and P while the
robot already turns and drives where an intention has formed.

Obstacles.  The robot's map is the scenario's static walls.  With
`obstacles = "told"` (the paper's case 3) the map also holds every scheduled
obstacle while it is present, as the original supervisor wrote it into the
map when it appeared and cleared it when it went.  With "sensed" the robot
marks on its map what its proximity sensors meet off the map, and shares it
with the other dft robots over swarm/<run>/context/** (context.py).  With
"unknown" obstacles reach it only through the action fields' proximity
inhibition.
"""

from __future__ import annotations

import time
from dataclasses import asdict
from typing import Any

import numpy as np

from agents.controllers.dft.architecture import EBS, spa_architecture
from agents.controllers.dft.context import SensedContext
from agents.controllers.dft.fields import Engine, fill_noise, noise_key
from agents.controllers.dft.params import DftParams, Interface, MapNoise, SpaParams
from agents.controllers.dft.robot import gaussian_2d, heading_images, ir_image, wheel_speeds
from agents.controllers.navigation.astar import occupancy

FIELD_STREAM, MAP_STREAM = 1, 2


MAP_NOISE = asdict(MapNoise())  # {"none": 0.005, "low": 0.05, "high": 1.0}


def check_table(table: dict[str, Any]) -> None:
    DftParams.from_table(table)


class DftController:
    def reset(self, seed: int, agent: int, params: dict[str, Any]) -> None:
        self.seed, self.agent = seed, agent
        self.p = DftParams.from_table(params.get("dft"))
        self.iface = Interface()
        robot = params["robot"]
        self.max_wheel = float(robot["max_wheel_speed"])
        m = params["map"]
        self.size = tuple(float(v) for v in m["size"])
        walls = occupancy(self.size, self.p.cell, np.asarray(m["rects"], np.float64).reshape(-1, 4),
                          np.asarray(m["segments"], np.float64).reshape(-1, 4))  # fmt: skip
        b = self.p.border
        if b:
            walls[: b + 1, :] = walls[-b:, :] = True  # south (one more, as the code) and north
            walls[:, :b] = walls[:, -(b + 1) :] = True  # west and east (one more)
        self.shape = walls.shape
        self.walls = walls
        self.obstacle_rects = []
        if self.p.obstacles == "told":
            for o in params.get("obstacles") or []:
                self.obstacle_rects.append((tuple(o["rect"]), int(o["appear"]), o.get("vanish")))
        self.noise_level = params.get("noise", "low")
        self.map_noise = MAP_NOISE[self.noise_level]
        self.position_peak = 1.2 if self.noise_level == "high" else 1.0
        self.engine = Engine(spa_architecture(self.shape, SpaParams()), keep_inputs=False)
        self.sensed: SensedContext | None = None
        self.shares = None
        self.received = 0  # cells other robots marked that reached this one
        if self.p.obstacles == "sensed":
            self.sensed = SensedContext(walls, self.p.cell, float(robot["radius"]), robot["ir_bearings"],
                                        robot["ir_mounts"],
                                        self.p.sense_margin, self.p.mark_radius, self.p.memory,
                                        self.p.min_reading)  # fmt: skip
            self.shares = "context"
        goal = params.get("goal")
        self.goal = None if goal is None else (float(goal[0]), float(goal[1]))
        if self.goal is not None:
            cj, ci = self._cell(*self.goal)
            self.engine.set_input("goal", gaussian_2d(self.shape, cj, ci, self.p.goal_sigma, self.p.goal_peak))
        self.tick = 0
        self.known = -1  # bit mask of the told obstacles now in the map
        self.told = walls  # walls and the told obstacles now present
        self.map_base = np.zeros(self.shape, np.float32)
        self.noise_buf = np.empty(self.shape, np.float32)
        self.last_wheels = np.zeros(2)

    def _cell(self, x: float, y: float) -> tuple[float, float]:
        """Continuous field coordinates (j, i) of a point: cell centres are integers."""
        return y / self.p.cell - 0.5, x / self.p.cell - 0.5

    def _context(self) -> np.ndarray:
        """-1 on walls and known obstacles, plus map noise (fresh every tick)."""
        known = 0
        for k, (_, appear, vanish) in enumerate(self.obstacle_rects):
            if self.tick >= appear and (vanish is None or self.tick < vanish):
                known |= 1 << k
        if known != self.known:  # the told obstacles are rasterised only when their set changes
            self.known = known
            rects = np.array([r for k, (r, _, _) in enumerate(self.obstacle_rects) if known >> k & 1],
                             np.float64).reshape(-1, 4)  # fmt: skip
            self.told = self.walls | occupancy(self.size, self.p.cell, rects, np.zeros((0, 4))) if known else self.walls
            self.map_base = -self.told.astype(np.float32)
        if self.sensed is not None:  # sensed marks change every tick
            self.map_base = -(self.told | self.sensed.blocked(self.tick)).astype(np.float32)
        fill_noise(np.uint64(noise_key(self.seed, self.agent, self.tick, MAP_STREAM)), self.noise_buf.ravel())
        return self.map_base + np.float32(self.map_noise) * self.noise_buf

    def step(self, perception: dict[str, np.ndarray], times: dict[str, float] | None = None) -> np.ndarray:
        """Wheel speeds (m/s) for this tick; `times`, if given, accumulates seconds per part (swarm bench dft)."""
        clock = time.perf_counter if times is not None else None
        t0 = clock() if clock else 0.0
        for need in ("position", "compass", "ir"):
            if need not in perception:
                raise ValueError("dft needs the position, compass and ir sensors (the epuck has them)")
        e = self.engine
        if self.tick % self.p.position_every == 0:
            x, y = (float(v) for v in perception["position"])
            cj, ci = self._cell(x, y)
            e.set_input("position", gaussian_2d(self.shape, cj, ci, self.p.position_sigma, self.position_peak))
        for d, img in heading_images(self.iface, float(perception["compass"])).items():
            e.set_input(f"heading_{d}", img)
        e.set_input("ir", ir_image(self.iface, perception["ir"]))
        if self.sensed is not None:
            self.sensed.sense(perception["position"], float(perception["compass"]), perception["ir"], self.tick)
        e.set_input("context", self._context())
        if clock:
            t1 = clock()
            times["sensor inputs"] = times.get("sensor inputs", 0.0) + t1 - t0
        e.step(noise_key(self.seed, self.agent, self.tick, FIELD_STREAM), times)
        self.tick += 1
        t0 = clock() if clock else 0.0
        left, right = wheel_speeds(self.iface, {d: e.output(f"A_{d}") for d in EBS})
        wheels = np.clip(np.array([left, right]) * self.p.wheel_unit, -self.max_wheel, self.max_wheel)
        self.last_wheels = wheels
        if clock:
            times["wheels"] = times.get("wheels", 0.0) + clock() - t0
        return wheels

    # ------------------------------------------------------------ sharing

    def publish(self) -> dict[str, Any] | None:
        """What this robot marked and cleared in its last step (sensed obstacles only)."""
        return None if self.sensed is None else self.sensed.publish(self.tick - 1)

    def receive(self, sender: int, data: Any) -> None:
        """Another robot's marks (ValueError if malformed)."""
        if self.sensed is not None:
            self.sensed.receive(data)
            self.received += len(data["marked"]) // 2

    def summary(self) -> dict[str, Any]:
        if self.sensed is None:
            return {}
        return {"context": {"marked_now": int(self.sensed.blocked(self.tick).sum()), "received": self.received}}

    # ----------------------------------------------------------- review

    def intentions(self) -> dict[str, float]:
        return {d: float(self.engine.output(f"I_{d}").max()) for d in EBS}

    def snapshot(self) -> dict[str, Any]:
        return {"tick": self.tick, "fields": self.engine.state(), "params": asdict(self.p), "received": self.received,
                "context": None if self.sensed is None else self.sensed.snapshot()}  # fmt: skip

    # restore() checks the whole state before it writes any of it: a memory that does not fit changes
    # nothing, so the agent needs no rollback copy of the old state (MBs: agents/arena_runtime.py)
    atomic_restore = True
    restore_copies = True  # put() writes the fields into the engine's arrays: it may be given views

    def restore(self, state: dict[str, Any]) -> None:
        tick, received = int(state["tick"]), int(state.get("received", 0))
        fields = self.engine.checked(state["fields"])
        context = None
        if self.sensed is not None and state.get("context") is not None:
            context = self.sensed.checked(state["context"])
        self.tick, self.received = tick, received
        self.engine.put(fields)
        if context is not None:
            self.sensed.put(context)
        self.known = -1

    def record(self) -> dict[str, np.ndarray]:
        e = self.engine
        return {
            "motivation": np.stack([e.u(f"M_{d}") for d in EBS]),
            "intention": np.stack([e.u(f"I_{d}") for d in EBS]),
            "intention_max": np.array(list(self.intentions().values())),
            "action": np.stack([e.output(f"A_{d}") for d in EBS]),
        }
