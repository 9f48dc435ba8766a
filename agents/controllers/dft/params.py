"""The dft model's one declared parameter set (Billing, Lowe & Sandamirskaya 2015): every number of
the SPA architecture, of the e-puck's faces to it and of the controller, each with its provenance.

PAPER: the paper's Table 2 and section 4 (the map noise, the obstacle of case 3).  CODE: the original
code (erikbilling/SPA, as shared/papers/dft-spa-data/parameters.md records it), where the paper gives
no number or the code's differs; docs/dft.md says which one we follow and why.  OURS: what neither
gives, each with its reason: the e-puck's wheel unit, and the obstacles a robot senses and shares.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from swarm.core.params import CODE, OURS, PAPER, declared
from swarm.core.tables import params_from_table


@dataclass(frozen=True)
class Lateral:
    """Interaction kernel of a field with itself (equation 2)."""

    c_exc: float = 0.0
    s_exc: float = 1.0
    c_inh: float = 0.0
    s_inh: float = 1.0
    c_global: float = 0.0  # every cell gets c_global * sum of the field's output


# Lateral kernels of the EB fields (c_exc, s_exc, c_inh, s_inh): the code and Table 2 agree.
LATERAL_M = Lateral(7.0, 2.0, 2.0, 4.0)
LATERAL_P = Lateral(4.0, 2.0, 2.0, 4.0)
LATERAL_I = Lateral(9.0, 2.0)
LATERAL_C = Lateral(2.0, 2.0, 2.0, 4.0)


@dataclass(frozen=True)
class SpaParams:
    """Every number of the architecture.  Defaults: the original code (erikbilling/SPA, as
    shared/papers/dft-spa-data/parameters.md records it); PAPER where the paper's Table 2 gives the
    same number, CODE where only the code gives it.
    """

    tau: float = declared(
        5.0, source=PAPER, where="Table 2: tau = 5 steps, all EB fields (the code agrees: setupMove.m)"
    )
    h: float = declared(-5.0, source=PAPER, where="Table 2: h = -5 (the code agrees: setupMove.m)")
    beta: float = declared(
        4.0, source=CODE, where="eb/setupMove.m: beta 4 for M, P, I, C (parameters.md section 3; not in the paper)"
    )
    field_noise: float = declared(
        1.0,
        source=CODE,
        where="eb/ElementaryBehavior.m: field noise amplitude 1 (parameters.md section 3; not in the paper)",
    )
    lateral_m: Lateral = declared(
        LATERAL_M,
        source=PAPER,
        where=(
            "Table 2: c_exc 7, s_exc 2, c_inh 2, s_inh 4 (the code agrees, eb/ElementaryBehavior.m, "
            "as normalised kernels: parameters.md sections 4, 14.1)"
        ),
    )
    lateral_p: Lateral = declared(
        LATERAL_P, source=PAPER, where="Table 2: 4, 2, 2, 4 (the code agrees, eb/ElementaryBehavior.m)"
    )
    lateral_i: Lateral = declared(
        LATERAL_I, source=PAPER, where="Table 2: 9, 2, 0 (the code agrees, eb/ElementaryBehavior.m)"
    )
    lateral_c: Lateral = declared(
        LATERAL_C, source=PAPER, where="Table 2: 2, 2, 2, 4 (the code agrees, eb/ElementaryBehavior.m)"
    )
    shift: int = declared(
        5, source=PAPER, where="Table 2: delta x, delta y = 5 cells (the code agrees: parameters.md section 0)"
    )
    sigma: float = declared(
        2.0,
        source=PAPER,
        where="Table 2: sigma = 2 (the code's Gauss(2) couplings: turnField.m, parameters.md section 5)",
    )
    c1: float = declared(12.0, source=PAPER, where="Table 2: c1 = 12 (the code agrees: turnField.m)")
    c2a: float = declared(
        5.0,
        source=PAPER,
        where=(
            "Table 2: c2a = 5 (the code: a plain copy shifted by delta, not the paper's Gaussian: "
            "parameters.md section 5)"
        ),
    )
    c2c: float = declared(4.5, source=PAPER, where="Table 2: c2c = 4.5 (the code agrees: turnField.m)")
    c2d: float = declared(-10.0, source=PAPER, where="Table 2: c2d = -10 (the code agrees: turnField.m)")
    c3: float = declared(10.0, source=PAPER, where="Table 2: c3 = 10 (the code agrees: turnField.m)")
    c4: float = declared(-10.0, source=PAPER, where="Table 2: c4 = -10 (the code agrees: turnField.m)")
    c5: float = declared(3.0, source=PAPER, where="Table 2: c5 = 3 (the code agrees: turnField.m)")
    c6: float = declared(-5.0, source=PAPER, where="Table 2: c6 = -5 (the code agrees: turnField.m)")
    c7: float = declared(
        -15.0,
        source=PAPER,
        where="Table 2: c7 = -15 (the code: a plain copy one cell forward: parameters.md section 5)",
    )
    c8: float = declared(8.0, source=PAPER, where="Table 2: c8 = 8 (the code agrees: turnField.m)")
    map_gain: float = declared(
        15.0,
        source=CODE,
        where=(
            "turnField.m: lambda, the map through Gauss(2) x 15 into every M (parameters.md section "
            "6; the paper gives no number)"
        ),
    )
    action_tau: float = declared(
        3.0,
        source=CODE,
        where=(
            "createTurnField.m: action fields tau 3 (parameters.md section 8; the paper: eq. 12 "
            "prints pi, Table 2 tau = 5)"
        ),
    )
    action_global: float = declared(
        -0.05,
        source=CODE,
        where="createTurnField.m: global inhibition -0.05 of the field's own output (parameters.md section 8)",
    )
    intention_gain: float = declared(
        2.0,
        source=CODE,
        where="turnField.m: S_I = 2 max f(u_I) (parameters.md section 8; the paper's eq. 13 weighs it 1)",
    )
    prox_tau: float = declared(5.0, source=CODE, where="turnField.m: proximity field tau 5 (parameters.md section 10)")
    prox_beta: float = declared(
        3.0, source=CODE, where="turnField.m: proximity field beta 3 (parameters.md section 10)"
    )
    prox_gain: float = declared(
        -16.0, source=CODE, where="turnField.m: S_O total -16 through a normalised Gauss(12) (parameters.md section 8)"
    )
    prox_sigma: float = declared(
        12.0, source=CODE, where="turnField.m: S_O's kernel, Gauss(12 cells) (parameters.md section 8)"
    )
    prox_boost: float = declared(
        0.01,
        source=CODE,
        where="turnField.m: + 0.01 sum f(u_prox), uniform (parameters.md section 8; not in the paper)",
    )


@dataclass(frozen=True)
class MapNoise:
    """Map noise, std per map cell, a wall being 1, at each noise level (MAP_NOISE is taken from it)."""

    none: float = declared(
        0.005,
        source=CODE,
        where="EBMap.m, initNoiseLevel.m: 0.005 in run sets tagged neither "
        "low nor high noise (parameters.md section 7)",
    )
    low: float = declared(
        0.05,
        source=PAPER,
        where="section 4: std = 5% of the contextual stimuli strength "
        "(lambda); the code agrees, 0.05 (parameters.md section 7)",
    )
    high: float = declared(
        1.0, source=PAPER, where="section 4: std of 100% of lambda; the code agrees, 1.0 (parameters.md section 7)"
    )


@dataclass(frozen=True)
class DftParams:
    cell: float = declared(
        0.01,
        source=CODE,
        where="turnField.m: 100 x 100 fields over the 1 m Z-maze, 1 cm cells (parameters.md section 2)",
    )
    border: int = declared(
        5,
        source=CODE,
        where=(
            "webots/setupMap.m: wall rows and columns 1..5 and N-5..N round the field (parameters.md "
            "section 6: 5 north and west, 6 south and east)"
        ),
    )
    goal_peak: float = declared(
        10.0,
        source=CODE,
        where=(
            "turnField.m: gamma, a plain Gaussian of peak 10 on the goal cell (parameters.md section "
            "6; the paper gives no number)"
        ),
    )
    goal_sigma: float = declared(
        3.0, source=CODE, where="turnField.m: the goal Gaussian's s = 3 cells (parameters.md section 6)"
    )
    position_sigma: float = declared(
        3.0,
        source=CODE,
        where=(
            "EPuckController.m: the robot position image, s = 3 (peak 1, 1.2 at high noise), into C "
            "with gain c8 (parameters.md section 5, row 8; the paper: sigma 2)"
        ),
    )
    position_every: int = declared(
        2,
        source=CODE,
        where="turnFieldSupervisor.py: a pose message every 128 ms, two 64 ms steps (parameters.md sections 6, 11)",
    )
    wheel_unit: float = declared(
        0.1288e-3,
        source=OURS,
        reason=(
            "m/s per e-puck wheel unit: the e-puck's 1000 steps/s are 12.88 cm/s (Mondada et al. "
            "2009); the code leaves it to Webots (docs/dft.md)"
        ),
    )
    obstacles: str = declared(
        "told",
        source=PAPER,
        where=(
            "section 4 (case 3): when an obstacle was added the map was updated with it (the "
            "supervisor wrote it into the map: parameters.md section 6)"
        ),
    )
    sense_margin: float = declared(
        0.03, source=OURS, reason="sensed (ours): a point this close to a wall of the map is the wall"
    )
    mark_radius: float = declared(
        0.04,
        source=OURS,
        reason="sensed (ours): the disc a point marks, the robot's radius: the room it takes from one passing",
    )
    memory: int = declared(300, source=OURS, reason="sensed (ours): ticks a mark lasts unless seen again, about 19 s")
    min_reading: float = declared(
        120.0, source=OURS, reason="sensed (ours): IR readings from this up count, 5 cm from the sensor on a white wall"
    )

    @classmethod
    def from_table(cls, table: dict[str, Any] | None) -> DftParams:
        p = params_from_table(cls, table, "dft", ints=("border", "position_every", "memory"), texts=("obstacles",))
        if p.obstacles not in ("told", "sensed", "unknown"):
            raise ValueError(f"[dft]: obstacles is 'told', 'sensed' or 'unknown', not {p.obstacles!r}")
        if p.cell <= 0 or p.position_every < 1 or p.border < 0 or p.memory < 1:
            raise ValueError("[dft]: cell must be > 0, position_every and memory >= 1, border >= 0")
        return p


@dataclass(frozen=True)
class SensorLayout:
    """Where each proximity sensor ps0..ps7 writes into the proximity field, and how much it counts
    (IR_CELLS and IR_WEIGHT are taken from it)."""

    cells: tuple[int, ...] = declared(
        (55, 65, 90, 100, 1, 10, 35, 45),
        source=PAPER,
        where="Table 2: x_r = 0.1, "
        "0.3, 0.8, 1.0, -1.0, -0.8, -0.3, -0.1 pi, = (cell / 50 - 1) pi: 1-based cells "
        "of the 100 over [-pi, pi) (the code agrees: EPuckController.m, parameters.md "
        "section 10)",
    )
    weight: tuple[float, ...] = declared(
        (1.0, 1.0, 0.5, 0.5, 0.5, 0.5, 1.0, 1.0),
        source=CODE,
        where="EPuckController.m: the rear and side sensors ps2..ps5 count half "
        "(parameters.md section 10; not in the paper)",
    )


@dataclass(frozen=True)
class Interface:
    """The e-puck's face to the fields (equations 8-11, 16-17; parameters.md sections 8-10): robot.py makes
    the heading and IR images and the wheel speeds from these numbers."""

    heading_gain: float = declared(
        4.0,
        source=CODE,
        where="turnField.m: S_H peak 4, fed directly (no head-direction field; parameters.md section 8)",
    )
    heading_sigma: float = declared(
        30.0, source=CODE, where="turnField.m: S_H's Gaussian, 30 cells (parameters.md section 8)"
    )
    prox_strength: float = declared(
        5.0,
        source=PAPER,
        where="Table 2 and eq. 17: c_prox = 5, strength c_prox ln(1 + p / 50) (the code agrees: EPuckController.m)",
    )
    prox_sigma: float = declared(
        3.0, source=PAPER, where="Table 2: sigma_prox = 3 cells (the code agrees: EPuckController.m)"
    )
    v: float = declared(
        500.0, source=PAPER, where="Table 2 and eq. 10: v = 500 wheel units (the code agrees: createTurnField.m)"
    )
    alpha: float = declared(
        math.pi / 3, source=PAPER, where="Table 2: alpha = pi/3 (the code agrees: createTurnField.m)"
    )
    turn_limit: float = declared(
        400.0,
        source=CODE,
        where="EPuckController.m: |left - right| at most 400 (parameters.md section 9; not in the paper)",
    )
