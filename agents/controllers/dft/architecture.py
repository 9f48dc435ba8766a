"""The SPA architecture of Billing, Lowe & Sandamirskaya (2015) as a table.

Four elementary behaviours (EBs), one per compass direction, each with
motivation M, precondition P, intention I and condition-of-satisfaction C
fields over the floor (1 cm cells); one action field per EB over the turning
angle; one proximity-sensor field.  Numbers are the original code's
(shared/papers/dft-spa-data/parameters.md), which the paper's Table 2 restates
in part; where the two differ, docs/dft.md says which we follow and why.

Field arrays are [j, i]: j counts cells northwards (y), i eastwards (x).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from agents.controllers.dft.fields import Architecture, Coupling, Field, Input, Lateral
from swarm.core.params import CODE, PAPER, declared

EBS = ("N", "S", "W", "E")
# Travel of each EB in cells (dj, di), and the heading (rad, CCW from east) its action field aims at.
TRAVEL = {"N": (1, 0), "S": (-1, 0), "W": (0, -1), "E": (0, 1)}
HEADING = {"N": math.pi / 2, "S": 3 * math.pi / 2, "W": math.pi, "E": 0.0}
OPPOSITE = {"N": "S", "S": "N", "W": "E", "E": "W"}
ORTHOGONAL = {"N": ("W", "E"), "S": ("W", "E"), "W": ("N", "S"), "E": ("N", "S")}
ANGLES = 100  # cells of the action and proximity fields over [-pi, pi)
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


def spa_architecture(shape: tuple[int, int], p: SpaParams = SpaParams()) -> Architecture:
    fields, couplings = [], []
    lateral = {"M": p.lateral_m, "P": p.lateral_p, "I": p.lateral_i, "C": p.lateral_c}
    for d in EBS:
        for kind in "MPIC":
            fields.append(Field(f"{kind}_{d}", shape, p.tau, p.h, p.beta, p.field_noise, lateral[kind]))
        dj, di = TRAVEL[d]
        fwd, back, step = (dj * p.shift, di * p.shift), (-dj * p.shift, -di * p.shift), (dj, di)
        couplings += [
            Coupling(f"M_{d}", f"P_{d}", p.c1, p.sigma, back),  # 1
            Coupling(f"P_{d}", f"M_{d}", p.c2a, None, back),  # 2a: back-chaining
            *(Coupling(f"P_{o}", f"M_{d}", p.c2c) for o in ORTHOGONAL[d]),  # 2c
            Coupling(f"P_{OPPOSITE[d]}", f"M_{d}", p.c2d),  # 2d: opposite EBs compete
            Coupling(f"M_{d}", f"I_{d}", p.c3, p.sigma),  # 3
            Coupling(f"P_{d}", f"I_{d}", p.c4, p.sigma, fwd),  # 4
            Coupling(f"I_{d}", f"C_{d}", p.c5, p.sigma),  # 5
            Coupling(f"C_{d}", f"I_{d}", p.c6, p.sigma),  # 6
            Coupling(f"C_{d}", f"P_{d}", p.c7, None, step),  # 7: release of precondition
            Coupling("position", f"C_{d}", p.c8),  # 8
            Coupling("goal", f"M_{d}", 1.0),  # gamma
            Coupling("context", f"M_{d}", p.map_gain, p.sigma),  # lambda
        ]
    for d in EBS:
        fields.append(Field(f"A_{d}", (ANGLES,), p.action_tau, p.h, p.beta, 0.0, Lateral(c_global=p.action_global)))
        couplings += [
            Coupling(f"heading_{d}", f"A_{d}", 1.0),  # S_H
            Coupling(f"I_{d}", f"A_{d}", p.intention_gain, reduce="max"),  # S_I
            Coupling("prox", f"A_{d}", p.prox_gain, p.prox_sigma),  # S_O
            Coupling("prox", f"A_{d}", p.prox_boost, reduce="sum"),
        ]
    fields.append(Field("prox", (ANGLES,), p.prox_tau, p.h, p.prox_beta))
    couplings.append(Coupling("ir", "prox", 1.0))
    inputs = [Input(n, shape) for n in ("goal", "context", "position")]
    inputs += [Input(f"heading_{d}", (ANGLES,)) for d in EBS] + [Input("ir", (ANGLES,))]
    return Architecture(tuple(fields), tuple(inputs), tuple(couplings))
