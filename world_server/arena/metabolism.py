"""The virtual metabolism of Girard et al. (2005), the world's side of it.

Each robot of a scenario with a [metabolism] table carries Energy E and
Potential Energy Ep in [0, 1].  E runs down so that a full load lasts 33
minutes (section 3.1); ReloadEp inside an ingesting zone raises Ep; ReloadE
inside a digesting zone turns Ep into E; a robot whose E reaches 0 is dead
(it stops where it is and stays an obstacle).  The paper gives neither the
reload rates nor what a dangerous area does: ours are in MetabolismParams and
docs/bg.md.  A robot reads its E and Ep as internal sensors ("metabolism").

A robot asks for a consummatory act with the third number of its action
(ACTS: 0 none, 1 ReloadE, 2 ReloadEp); an act outside a zone of its kind does
nothing but is counted.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numba import njit

from swarm.core.params import OURS, PAPER, declared
from world_server.arena.face.sensors.zones import ZONE_KINDS

ACTS = ("none", "ReloadE", "ReloadEp")
ACT_ZONE = {1: "digesting", 2: "ingesting"}  # the zone kind each act needs
STOPS = ("death", "ingest")


_ZONE_OF_ACT = np.array([0] + [1 << ZONE_KINDS.index(ACT_ZONE[code]) for code in (1, 2)], np.int64)  # by ACTS code
_DANGEROUS = 1 << ZONE_KINDS.index("dangerous")


@njit(cache=True)
def _metabolise(acts: np.ndarray, zone_bits: np.ndarray, moving: np.ndarray, alive: np.ndarray, energy: np.ndarray,
                potential: np.ndarray, done: np.ndarray, idle: np.ndarray, died_tick: np.ndarray, tick: int,
                ingest: float, digest: float, loss: float, danger: float, ingest_tick: np.ndarray,
                first: np.ndarray) -> bool:  # fmt: skip
    """One control period in place (`ingest`, `digest`, `loss`, `danger` are the period's amounts): living robots
    in `moving` do their acts where their zone bits allow (else the act is idle), every living robot's E runs
    down (more within a dangerous area's reach), and one whose E reaches 0 dies.  Marks in `first` the robots
    whose ReloadEp worked for the first time; True if any.  Each amount in the order of operations of the
    numpy expressions this replaced (their numbers to the bit)."""
    any_first = False
    for i in range(acts.shape[0]):
        code = acts[i]
        if alive[i] and moving[i] and (code == 1 or code == 2):
            if (zone_bits[i] & _ZONE_OF_ACT[code]) == 0:
                idle[i] += 1
            elif code == 2:  # ReloadEp
                done[i, 2] += 1
                potential[i] = min(1.0, potential[i] + ingest)
                if ingest_tick[i] < 0:
                    first[i] = any_first = True
            else:  # ReloadE: Ep becomes E, as much as there is of one and room for the other
                done[i, 1] += 1
                gain = max(min(min(digest, potential[i]), 1.0 - energy[i]), 0.0)
                energy[i] = energy[i] + gain
                potential[i] = potential[i] - gain
        if alive[i]:
            energy[i] = max(energy[i] - (loss + (danger if zone_bits[i] & _DANGEROUS else 0.0)), 0.0)
            if energy[i] <= 0.0:
                died_tick[i] = tick
                alive[i] = False
    return any_first


@dataclass(frozen=True)
class MetabolismParams:
    """E and Ep of Girard et al. (2005), section 3.1: the paper gives the 33-minute lifetime and
    nothing else (docs/bg.md, Metabolism)."""

    energy: float = declared(1.0, source=PAPER, where="section 3.1: a full load of Energy; section 4.3.1: E = 1")
    potential: float = declared(
        1.0,
        source=OURS,
        reason="Ep at the start: the paper gives none for experiment 1 (experiment 3.1 only Ep < 1); full, as E",
    )
    lifetime: float = declared(1980.0, source=PAPER, where="section 3.1: a full load of Energy lasts 33 min (1980 s)")
    ingest_rate: float = declared(
        0.1,
        source=OURS,
        reason="Ep gained per second of ReloadEp in an ingesting zone: "
        "a full load in 10 s of eating; the paper gives no rate (docs/bg.md)",
    )
    digest_rate: float = declared(
        0.1,
        source=OURS,
        reason="E gained (and Ep spent) per second of ReloadE in a digesting zone, likewise (docs/bg.md, Metabolism)",
    )
    danger_rate: float = declared(
        0.01,
        source=OURS,
        reason="extra E lost per second within a dangerous area's reach: "
        "crossing one costs about 4% of E, worth avoiding, not fatal (docs/bg.md)",
    )
    stop_at: str = declared(
        "death",
        source=OURS,
        reason="the run ends when every robot is dead (experiment 1 "
        "measures survival); experiments 2 and 3 set 'ingest'",
    )

    @classmethod
    def from_table(cls, table: dict[str, Any]) -> MetabolismParams:
        """Raise ValueError (one line, naming the field) on a bad [metabolism] table."""
        known = {f.name for f in fields(cls)}
        for k, v in table.items():
            if k not in known:
                raise ValueError(f"metabolism.{k}: unknown; expected one of {', '.join(sorted(known))}")
            if k == "stop_at":
                if v not in STOPS:
                    raise ValueError(f"metabolism.stop_at: expected one of {', '.join(STOPS)}, got {v!r}")
                continue
            if not isinstance(v, int | float) or isinstance(v, bool) or not np.isfinite(v) or v < 0:
                raise ValueError(f"metabolism.{k}: expected a number >= 0, got {v!r}")
            if k in ("energy", "potential") and v > 1:
                raise ValueError(f"metabolism.{k}: expected a level in [0, 1], got {v!r}")
        if table.get("lifetime", 1.0) == 0:
            raise ValueError("metabolism.lifetime: expected a positive number of seconds")
        return cls(**{k: (v if k == "stop_at" else float(v)) for k, v in table.items()})


class Metabolism:
    """E and Ep of n robots, stepped once per control period of `dt` seconds."""

    STATE = ("energy", "potential", "alive", "died_tick", "ingest_tick", "ingest_resource", "acts", "idle_acts")

    def __init__(self, n: int, params: MetabolismParams, dt: float, resources: list[tuple[str, str, tuple]]):
        """`resources`: (name, zone kind, centre) of every resource, in the scenario's order."""
        self.p, self.dt, self.resources = params, dt, resources
        self.energy = np.full(n, params.energy)
        self.potential = np.full(n, params.potential)
        self.alive = self.energy > 0
        self.died_tick = np.where(self.alive, -1, 0).astype(np.int64)
        self.ingest_tick = np.full(n, -1, np.int64)  # first ReloadEp that worked
        self.ingest_resource = np.full(n, -1, np.int64)  # ... at which resource
        self.acts = np.zeros((n, len(ACTS)), np.int64)  # acts that worked, per kind
        self.idle_acts = np.zeros(n, np.int64)  # acts asked for outside a zone of their kind

    def levels(self, rows: np.ndarray) -> np.ndarray:
        """(E, Ep) of these robots: their internal sensors."""
        return np.column_stack([self.energy[rows], self.potential[rows]])

    def step(self, acts: np.ndarray, zone_bits: np.ndarray, moving: np.ndarray, xy: np.ndarray, tick: int) -> None:
        """One control period: robots in `moving` (alive, present, acting) do their
        acts where their zones allow; every living robot's E runs down."""
        p, dt = self.p, self.dt
        first = np.zeros(len(acts), np.bool_)
        if _metabolise(np.ascontiguousarray(acts, np.int64), np.ascontiguousarray(zone_bits, np.int64),
                       np.ascontiguousarray(moving, np.bool_), self.alive, self.energy, self.potential, self.acts,
                       self.idle_acts, self.died_tick, tick, p.ingest_rate * dt, p.digest_rate * dt,
                       dt / p.lifetime, p.danger_rate * dt, self.ingest_tick, first):  # fmt: skip
            for a in np.flatnonzero(first):  # a first ReloadEp that worked: at which resource
                self.ingest_tick[a] = tick
                self.ingest_resource[a] = self._nearest(xy[a], ACT_ZONE[2])

    def _nearest(self, xy: np.ndarray, kind: str) -> int:
        best, which = np.inf, -1
        for k, (_, z, centre) in enumerate(self.resources):
            d = float(np.hypot(xy[0] - centre[0], xy[1] - centre[1]))
            if z == kind and d < best:
                best, which = d, k
        return which

    def done(self) -> bool:
        if self.p.stop_at == "ingest":
            return bool(((self.ingest_tick >= 0) | ~self.alive).all())
        return not self.alive.any()

    def summary(self, agent: int, dt: float, ticks: int) -> dict[str, Any]:
        died = int(self.died_tick[agent])
        r = int(self.ingest_resource[agent])
        return {
            "alive": bool(self.alive[agent]),
            "energy": round(float(self.energy[agent]), 5),
            "potential": round(float(self.potential[agent]), 5),
            "survival_seconds": round((died if died >= 0 else ticks) * dt, 2),
            "died_tick": died if died >= 0 else None,
            "ingested": self.resources[r][0] if r >= 0 else None,
            "ingest_tick": int(self.ingest_tick[agent]) if self.ingest_tick[agent] >= 0 else None,
            "reloads": {ACTS[k]: int(self.acts[agent, k]) for k in (1, 2)},
            "idle_acts": int(self.idle_acts[agent]),
        }

    def snapshot(self) -> dict[str, np.ndarray]:
        return {f"metabolism_{k}": np.array(getattr(self, k)) for k in self.STATE}

    def restore(self, state: dict[str, np.ndarray]) -> None:
        for k in self.STATE:
            setattr(self, k, np.array(state[f"metabolism_{k}"]))
