"""The BG animat (Girard et al. 2005): two basal-ganglia loops select what to
do from saliences that mix taxon, topological planning and exploration.

Each control period the animat reads its camera, sonars, odometry, compass
and internal sensors (E, Ep), updates its map, computes the saliences, lets
the GPR loops settle for the period (gpr.py, 1 ms Euler steps), and acts:
a dorsal selection (ReloadE or ReloadEp) stops it and asks the world for the
act; else it heads for the ventral loop's direction; the sonar reflex
overrides both when something is too close in front.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from agents.controllers.bg.colony import ColonyMap
from agents.controllers.bg.gpr import BasalGanglia, select_dorsal, select_ventral
from agents.controllers.bg.params import SALIENCES, WAYS, BgParams, GprParams, NavParams
from agents.controllers.bg.places import DIRECTIONS, Navigator
from agents.controllers.bg.saliences import Drives, saliences
from agents.controllers.bg.senses import RESOURCES, Reflex, sense
from swarm.core.tables import params_from_table

FEEDBACK = ("rest", "literal")  # BgParams.feedback
GPR_RUNTIME = ("cross", "dopamine")  # the [bg.gpr] fields a run may change
DORSAL_ACTS = ("ReloadE", "ReloadEp")  # channel order; world_server.arena.metabolism.ACTS codes 1, 2


def bg_params(table: dict[str, Any] | None) -> BgParams:
    """The [bg] table read into BgParams, its [bg.navigation] table checked: ValueError in one line."""
    table = dict(table or {})
    nav = table.pop("navigation", None)
    if isinstance(table.get("map"), dict):
        table.pop("map")  # a map given as data (experiments): read by the controller
    gpr = table.pop("gpr", None)
    p = params_from_table(BgParams, table, "bg", texts=("saliences", "map", "planning", "learn_map", "share",
                                                        "feedback", "hold_wheels"))  # fmt: skip
    for name in ("planning", "learn_map", "share", "hold_wheels"):
        if not isinstance(getattr(p, name), bool):
            raise ValueError(f"[bg]: {name} expected true or false, got {getattr(p, name)!r}")
    if p.saliences not in SALIENCES:
        raise ValueError(f"bg.saliences: expected one of {', '.join(SALIENCES)}, got {p.saliences!r}")
    if p.feedback not in FEEDBACK:
        raise ValueError(f"bg.feedback: expected one of {', '.join(FEEDBACK)}, got {p.feedback!r}")
    if nav is not None:
        nav_params(nav)
    if gpr is not None:
        gpr_params(gpr)
    return p


def gpr_params(table: dict[str, Any] | None) -> GprParams:
    """[bg.gpr]: the GPR's numbers a run may change (an ablation): eq. 10's cross weight and the dopamine
    level lambda; the rest are written into the GPR's compiled kernel."""
    table = dict(table or {})
    if fixed := sorted(set(table) - set(GPR_RUNTIME)):
        raise ValueError(f"[bg.gpr]: {fixed[0]!r} cannot change per run; only {', '.join(GPR_RUNTIME)} can")
    return params_from_table(GprParams, table, "bg.gpr")


def nav_params(table: dict[str, Any] | None) -> NavParams:
    p = params_from_table(NavParams, table, "bg.navigation", ints=("known_age",), texts=("ways",))
    if p.ways not in WAYS:
        raise ValueError(f"bg.navigation.ways: expected one of {', '.join(WAYS)}, got {p.ways!r}")
    if not 0.0 <= p.known_explore <= 1.0:
        raise ValueError(f"bg.navigation.known_explore: expected a number in [0, 1], got {p.known_explore!r}")
    return p


def check_table(table: dict[str, Any]) -> None:
    bg_params(table)


class BgController:
    def reset(self, seed: int, agent: int, params: dict[str, Any]) -> None:
        table = params.get("bg") or {}
        self.p = bg_params(table)
        self.nav_params = nav_params(table.get("navigation"))
        robot = params["robot"]
        self.axle, self.max_speed = float(robot["axle"]), float(robot["max_speed"])
        self.max_wheel = float(robot["max_wheel_speed"])
        self.max_turn = float(robot["max_turn_rate"])
        self.dt = float(params["control_period"])
        self.agent, self.tick = agent, 0
        gpr = gpr_params(table.get("gpr"))
        self.bg = BasalGanglia(cross=gpr.cross, dopamine=gpr.dopamine,
                               literal_feedback=self.p.feedback == "literal")  # fmt: skip
        self.nav = Navigator(self.nav_params, seed, agent, RESOURCES, mapping=self.p.learn_map)
        # P(DA) counts only in experiment 3.1's eq. 1: elsewhere its row of the plans stays 0
        self.plan_for = tuple((k, r) for k, r in enumerate(RESOURCES) if r != "DA" or self.p.saliences == "fear")
        given = table.get("map") if isinstance(table.get("map"), dict) else None
        if self.p.map:
            try:
                given = json.loads(Path(self.p.map).read_text())
            except (OSError, ValueError) as e:
                raise ValueError(f"bg.map: cannot read {self.p.map} ({e}); give a file BgController.map_data() "
                                 "wrote") from None  # fmt: skip
        if given is not None:
            self.nav.from_data(given)
            self.nav.lost()  # put down at its start: where that is on the map, its first view says
        # a colony shares its map (colony.py); an animat without one (condition B) has nothing to share
        self.shares = "map" if self.p.share and self.p.planning else None
        self.colony = ColonyMap(self.nav, agent)
        self.reflex = Reflex(self.p.too_close, self.p.reflex_hold)
        self.acting = -1  # the dorsal channel selected last tick
        self.last: dict[str, Any] = {}

    # ---------------------------------------------------------------- step

    def step(self, perception: dict[str, np.ndarray]) -> np.ndarray:
        levels = perception.get("metabolism")
        energy, potential = (float(levels[0]), float(levels[1])) if levels is not None else (1.0, 1.0)
        heading = float(perception["compass"])
        grey, sonar = perception["camera_grey"], np.asarray(perception["sonar"], np.float64)
        self.nav.move(float(perception["odometry"][0]), heading)
        prox, seen = sense(grey, heading)
        # A(res): mProx(res) = 1, the resource fills a whole 7-pixel window (section 3.2): the camera's, not the world's
        full = (prox == 1.0).any(axis=1)
        usable = {r: bool(full[k]) for k, r in enumerate(RESOURCES)}
        if self.p.planning:
            if self.nav.due():
                self.colony.adopt(self.nav.observe(grey, sonar, heading))
            self.nav.learn(usable, {r: bool(seen[k]) for k, r in enumerate(RESOURCES)}, self.dt)
            plan = np.zeros((len(RESOURCES), DIRECTIONS))
            for k, r in self.plan_for:
                plan[k] = self.nav.plan(r)
            bka, disorientation = self.nav.back_to_known(), self.nav.D
        else:
            plan, bka, disorientation = np.zeros((3, DIRECTIONS)), np.zeros(DIRECTIONS), 0.0
        drives = Drives(energy, potential, self.p.fear, disorientation, prox,
                        np.array([usable[r] for r in RESOURCES]), plan, bka,
                        self.nav.explore(sonar, heading, self.tick * self.dt, self.p.planning))  # fmt: skip
        s_dorsal, s_ventral, planned = saliences(drives, self.p.saliences,
                                                 self.p.w_plan if self.p.planning else 0.0, self.p.w_taxon)  # fmt: skip
        self.bg.run(s_dorsal, s_ventral, self.dt)
        d, v = self.bg.disinhibition()
        chosen = select_dorsal(d, self.p.dorsal_threshold, self.acting)
        self.acting = chosen
        direction, strength = select_ventral(v, self.p.ventral_threshold, self.p.ventral_min_share)
        reflex = self.reflex(sonar, self.dt) if chosen < 0 else None
        act = chosen + 1  # 0: none
        if chosen >= 0 and self.p.hold_wheels:
            forward, turn = 0.0, 0.0
        elif reflex is not None:
            forward, turn = reflex[0] * self.max_speed, reflex[1] * self.max_turn
        elif strength > 0:
            forward, turn = self._steer(direction, heading, float(sonar[0]))
        else:
            forward, turn = 0.0, 0.0
        # both wheels within their limit: the turn is kept, the forward speed gives way
        room = max(self.max_wheel - abs(turn) * self.axle / 2, 0.0)
        forward = min(max(forward, -room), room)
        self.tick += 1
        self.last = {"drives": drives, "s_dorsal": s_dorsal, "s_ventral": s_ventral, "dorsal": d, "ventral": v,
                     "act": act, "direction": direction if strength > 0 else math.nan, "reflex": reflex is not None,
                     "plan": planned}  # fmt: skip
        return np.array([forward - turn * self.axle / 2, forward + turn * self.axle / 2, float(act)])

    def _steer(self, direction: float, heading: float, ahead: float) -> tuple[float, float]:
        """Turn towards `direction` as fast as the body allows (10 degrees a second); go forward only when
        within `align` of it, slower the farther off and the nearer a wall ahead: a turn made while
        driving at full speed would carry the animat a metre sideways into the walls."""
        err = (direction - heading + math.pi) % (2 * math.pi) - math.pi
        turn = min(max(err / self.dt, -self.max_turn), self.max_turn)  # np.clip's numbers, without its cost
        room = min(max((ahead - self.p.too_close) / self.p.too_close, 0.0), 1.0)
        forward = self.max_speed * max(0.0, 1.0 - abs(err) / self.p.align) * (0.25 + 0.75 * room)
        return forward, turn

    # ------------------------------------------------------------ state

    def publish(self) -> dict[str, Any] | None:
        """What changed in the map and in what its places hold, for the colony."""
        return self.colony.publish() if self.shares else None

    def receive(self, sender: int, data: Any) -> None:
        """Merge another animat's publication (ValueError if malformed)."""
        self.colony.receive(sender, data)

    def map_data(self) -> dict[str, Any]:
        """The map and what its nodes hold, as plain data (JSON-safe): save it, load it with [bg] map."""
        return self.nav.to_data()

    def snapshot(self) -> dict[str, Any]:
        return {"tick": self.tick, "bg": {k: v.tolist() for k, v in self.bg.state().items()},
                "nav": self.nav.to_data(), "reflex": self.reflex.state(), "acting": self.acting,
                "colony": self.colony.to_data(), "params": asdict(self.p), "habits": self.nav.habits()}  # fmt: skip

    def restore(self, state: dict[str, Any]) -> None:
        self.tick = int(state["tick"])
        self.bg.restore({k: np.array(v, np.float64) for k, v in state["bg"].items()})
        self.nav.from_data(state["nav"])
        self.colony = ColonyMap(self.nav, self.agent)  # on the restored map
        self.colony.restore(state["colony"])
        self.reflex.restore(state["reflex"])
        self.acting = int(state["acting"])
        if "habits" in state:
            self.nav.take_habits(state["habits"])

    def record(self) -> dict[str, np.ndarray]:
        if not self.last:
            return {}
        dr: Drives = self.last["drives"]
        m = self.nav.map
        holds = [" ".join(r for r, w in self.nav.assoc.items() if len(w) > k and w[k] > 0.5)
                 for k in range(len(m.nodes))]  # fmt: skip
        return {
            "energy": np.array(dr.energy), "potential": np.array(dr.potential),
            "disorientation": np.array(dr.disorientation),
            "motivations": np.array([dr.m_e, dr.m_ep, dr.disorientation, dr.fear]),
            "dorsal": self.last["dorsal"], "ventral": self.last["ventral"],
            "act": np.array(self.last["act"]), "direction": np.array(self.last["direction"]),
            "reflex": np.array(self.last["reflex"]),
            # the map, for agents/controllers/navigation/recording.py: node, nodes, links, belief, and what nodes hold
            "node": np.array(m.current), "nodes": np.array(m.size), "folded": np.array(sorted(m.folded), np.int64),
            "links": np.array(list(m.links), np.int64).reshape(-1, 2), "belief": np.asarray(m.belief, np.float64),
            "holds": np.array(holds, dtype=object),
        }  # fmt: skip

    def summary(self) -> dict[str, Any]:
        m = self.nav.map
        held = {r: int((w > 0.5).sum()) for r, w in self.nav.assoc.items()}
        out = {
            "nodes": m.size,
            "links": len(m.links),
            "loops_closed": m.closures,
            "disorientation": round(self.nav.D, 4),
            "nodes_holding": held,
        }
        if self.shares:
            out |= {"from_others": self.colony.shared.added, "merged_with_ours": self.colony.shared.merged,
                    "holds_heard": self.colony.heard}  # fmt: skip
        return {"map": out}
