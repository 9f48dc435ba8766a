"""The wander controller: obstacle avoidance plus a seeded random walk.

It reads whichever range sensor the robot has (laser, sonar or IR) and sees
"in front" the readings within +-60 degrees of its heading.  Something closer
than `avoid` (in robot radii from the centre) turns it away from the nearer
side, on the spot when very close; otherwise it drives at `speed` of its wheel
limit and every tick starts a random turn with probability `turn_chance`, held
for a random number of ticks.  Every random number is swarm.core.rng's draw keyed by
(seed, agent, tick), so a run is reproducible in either runtime.  It needs no
map and no position: the baseline for exploring, and a second controller for
mixed arenas.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from swarm.core.params import OURS, declared
from swarm.core.rng_scalar import draw_unit
from swarm.core.tables import params_from_table
from world_server.arena.face.sensors.ir import IR_DISTANCE, IR_VALUE


@dataclass(frozen=True)
class WanderParams:
    """A reactive explorer of ours, for no paper: every value is ours."""

    speed: float = declared(
        0.6, source=OURS, reason="share of the wheel limit: fast enough to explore, slow enough to turn away in time"
    )
    avoid: float = declared(
        3.0,
        source=OURS,
        reason="react to obstacles this many robot radii from the centre: room to turn on the spot before touching",
    )
    turn_chance: float = declared(
        0.05, source=OURS, reason="per tick: a random turn about every 20 ticks, so straight runs cross a room"
    )
    turn_ticks: int = declared(15, source=OURS, reason="longest random turn, in ticks")

    @classmethod
    def from_table(cls, table: dict[str, Any] | None) -> WanderParams:
        return params_from_table(cls, table, "wander", ints=("turn_ticks",))


FRONT = math.radians(60)


class WanderController:
    def reset(self, seed: int, agent: int, params: dict[str, Any]) -> None:
        self.seed, self.agent = np.int64(seed), agent
        self.p = WanderParams.from_table(params.get("wander"))
        robot = params["robot"]
        self.radius, self.axle = float(robot["radius"]), float(robot["axle"])
        self.max_wheel = float(robot["max_wheel_speed"])
        # where the IR sensors look and sit (their readings count from their mounts); none without IR
        self.ir_bearings = np.asarray(robot.get("ir_bearings") or (), np.float64)
        self.ir_mounts = np.asarray(robot.get("ir_mounts") or (), np.float64)
        self.rab_payload = robot.get("rab_payload")  # bytes it broadcasts to its neighbours; None without the sensor
        self.tick = 0
        self.turning = 0  # ticks of random turn left (sign: direction)

    def _front(self, perception: dict[str, np.ndarray]) -> tuple[float, float] | None:
        """Nearest distance (from the centre) on the left and on the right half of the front, or None."""
        for name in ("laser", "sonar", "ir"):
            if name not in perception:
                continue
            values = np.asarray(perception[name], np.float64)
            n = len(values)
            if name == "ir":  # readings to distances from the centre: invert the response curve, add the mount
                dist = np.where(values > 0, np.interp(-values, -IR_VALUE, IR_DISTANCE) + self.ir_mounts[:n], np.inf)
                bearings = self.ir_bearings[:n]
            else:
                dist, bearings = values, np.arange(n) * 2 * math.pi / n
            bearings = (bearings + math.pi) % (2 * math.pi) - math.pi
            front = np.abs(bearings) <= FRONT
            left, right = front & (bearings > 0), front & (bearings <= 0)
            return (float(dist[left].min()) if left.any() else math.inf,
                    float(dist[right].min()) if right.any() else math.inf)  # fmt: skip
        return None

    def step(self, perception: dict[str, np.ndarray]) -> np.ndarray:
        tick = self.tick
        self.tick += 1
        v, turn = self.p.speed * self.max_wheel, 0.0
        front = self._front(perception)
        reach = self.p.avoid * self.radius
        if front is not None and min(front) < reach:
            away = -1.0 if front[0] < front[1] else 1.0  # obstacle on the left: turn right
            closeness = 1.0 - min(front) / reach
            turn, v = away * self.max_wheel, v * max(0.0, 1.0 - 2.0 * closeness)
            self.turning = 0
        else:
            if self.turning == 0 and draw_unit(self.seed, self.agent, tick, 0) < self.p.turn_chance:
                ticks = 1 + int(draw_unit(self.seed, self.agent, tick, 1) * self.p.turn_ticks)
                self.turning = ticks if draw_unit(self.seed, self.agent, tick, 2) < 0.5 else -ticks
            if self.turning:
                turn = math.copysign(0.5 * self.max_wheel, self.turning)
                self.turning -= int(math.copysign(1, self.turning))
        left, right = v - turn / 2, v + turn / 2
        top = max(abs(left), abs(right))
        if top > self.max_wheel:
            left, right = left * self.max_wheel / top, right * self.max_wheel / top
        return np.array([left, right])

    def broadcast(self) -> bytes | None:
        """Who it is and how many ticks it has wandered (little-endian uint16 each; the world cuts or pads it
        to the payload) to the neighbours its range-and-bearing sensor reaches: a tag to build a swarm on."""
        if self.rab_payload is None:
            return None
        return (np.array([self.agent, self.tick], np.int64) % 65536).astype("<u2").tobytes()

    def snapshot(self) -> dict[str, Any]:
        return {"tick": self.tick, "turning": self.turning, "params": asdict(self.p)}

    def restore(self, state: dict[str, Any]) -> None:
        self.tick, self.turning = int(state["tick"]), int(state["turning"])

    def record(self) -> dict[str, np.ndarray]:
        return {"turning": np.array(self.turning)}
