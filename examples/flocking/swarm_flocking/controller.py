"""Reynolds (1987) flocking on what an e-puck with a range-and-bearing board senses.

Each robot steers by the sum of four unit-free vectors in its own frame (x ahead, y left):

- separation: away from every neighbour nearer than `separation` metres, harder the nearer;
- cohesion: towards the neighbours' centre (their mean relative position);
- alignment: towards the neighbours' mean heading, which each broadcasts (its compass reading as a
  uint16) on the range-and-bearing board, relative to its own compass heading;
- avoidance: away from what its IR sensors see, and a constant pull ahead (`cruise`).

It sees no positions and no identities: distances and bearings of the neighbours in range and in
sight, their broadcast headings, its own compass and IR.  A robot that also carries this package's
`neighbour_count` sensor (swarm_flocking.sensor) records how crowded it is.  It drives at `speed` of its wheel limit,
slower the further the wanted direction is from its heading, and turns in proportion to that angle.
"""

from __future__ import annotations

import math
import struct
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from swarm.core.params import OURS, declared
from swarm.core.tables import params_from_table

HEADING_SCALE = 65536 / (2 * math.pi)  # a heading in [0, 2 pi) as a uint16


def ours(value: float, reason: str) -> Any:
    return declared(value, source=OURS, reason=reason)


@dataclass(frozen=True)
class FlockingParams:
    """The weights of the four rules and the drive; [flocking] in a scenario sets them.  Reynolds
    (1987) gives the rules, not numbers: every value is ours, with its reason (swarm.core.params)."""

    separation: float = ours(0.15, "metres: neighbours nearer than four e-puck diameters push away")
    w_separation: float = ours(1.5, "stronger than cohesion, so a flock does not collapse onto itself")
    w_cohesion: float = ours(1.0, "the unit the other weights are measured against")
    w_alignment: float = ours(1.0, "as strong as cohesion: neither heading nor gathering dominates")
    w_avoid: float = ours(3.0, "walls outrank the flock: a robot pressed against a wall by its neighbours turns away")
    cruise: float = ours(0.3, "a pull straight ahead, so a lone robot explores instead of spinning")
    speed: float = ours(0.8, "share of the wheel limit at full drive, leaving room to turn")
    turn_gain: float = ours(2.0, "wheel speed difference per pi radians of error, as a share of the wheel limit")

    @classmethod
    def from_table(cls, table: dict[str, Any] | None) -> FlockingParams:
        """swarm's table reader: an unknown field or a value that is no number is one line."""
        p = params_from_table(cls, table, "flocking")
        if any(v < 0 for v in asdict(p).values()):
            raise ValueError("[flocking]: expected numbers >= 0")
        return p


def unit(angles: np.ndarray) -> np.ndarray:
    return np.stack([np.cos(angles), np.sin(angles)], axis=-1)


class Flocking:
    """Reynolds flocking: separation, cohesion and alignment over the range-and-bearing board."""

    requires = ("range_and_bearing", "compass", "ir")
    parameters = ("swarm_flocking.controller:FlockingParams",)
    example = str(Path(__file__).parents[1] / "flock.toml")  # the package's scenario, from any folder

    def reset(self, seed: int, agent: int, params: dict[str, Any]) -> None:
        self.p = FlockingParams.from_table(params.get("table"))
        robot = params["robot"]
        self.max_wheel = float(robot["max_wheel_speed"])
        self.ir_bearings = np.asarray(robot.get("ir_bearings") or (), np.float64)
        self.heading = 0.0
        self.neighbours = 0
        self.counts = robot.get("neighbour_radius") is not None  # it carries neighbour_count
        self.crowd = 0
        self.wanted = 0.0
        self.ticks = 0

    def _rules(self, perception: dict[str, np.ndarray]) -> np.ndarray:
        count = int(perception["rab_count"])
        distance = np.asarray(perception["rab_distance"], np.float64)[:count]
        bearing = np.asarray(perception["rab_bearing"], np.float64)[:count]
        data = np.asarray(perception["rab_data"], np.uint8)[:count]
        self.neighbours = count
        p, want = self.p, np.array([self.p.cruise, 0.0])
        if count:
            towards = unit(bearing)
            near = distance < p.separation
            if near.any():
                push = (p.separation - distance[near]) / p.separation
                want -= p.w_separation * (push[:, None] * towards[near]).sum(axis=0)
            want += p.w_cohesion * (distance[:, None] * towards).mean(axis=0) / max(p.separation, 1e-9)
            theirs = data[:, 0].astype(np.float64) + 256.0 * data[:, 1]
            want += p.w_alignment * unit(theirs / HEADING_SCALE - self.heading).mean(axis=0)
        ir = np.asarray(perception.get("ir", ()), np.float64)
        if len(ir) and ir.max() > 150:  # within about 4 cm of something (world_server IR response)
            want -= p.w_avoid * (np.clip(ir, 0, 4095)[:, None] / 4095 * unit(self.ir_bearings[: len(ir)])).sum(axis=0)
        return want

    def step(self, perception: dict[str, np.ndarray]) -> np.ndarray:
        self.ticks += 1
        self.heading = float(perception["compass"]) % (2 * math.pi)
        if self.counts:
            self.crowd = int(perception["neighbour_count"])
        want = self._rules(perception)
        self.wanted = math.atan2(want[1], want[0])
        v = self.p.speed * self.max_wheel * max(0.0, math.cos(self.wanted))
        turn = self.p.turn_gain * self.max_wheel * self.wanted / math.pi
        left, right = v - turn / 2, v + turn / 2
        top = max(abs(left), abs(right), self.max_wheel)
        return np.array([left, right]) * (self.max_wheel / top)

    def broadcast(self) -> bytes:
        """Its compass heading, for the neighbours' alignment (two of the board's four bytes)."""
        return struct.pack("<HH", int(self.heading * HEADING_SCALE) % 65536, 0)

    def snapshot(self) -> dict[str, Any]:
        return {"heading": self.heading, "ticks": self.ticks, "params": asdict(self.p)}

    def restore(self, state: dict[str, Any]) -> None:
        self.heading, self.ticks = float(state["heading"]), int(state["ticks"])

    def record(self) -> dict[str, Any]:
        out = {"neighbours": self.neighbours, "wanted_turn": self.wanted, "heading": self.heading}
        return out | ({"crowd": self.crowd} if self.counts else {})

    check_table = staticmethod(FlockingParams.from_table)
