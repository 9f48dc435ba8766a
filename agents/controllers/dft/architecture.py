"""The SPA architecture of Billing, Lowe & Sandamirskaya (2015) as a table.

Four elementary behaviours (EBs), one per compass direction, each with
motivation M, precondition P, intention I and condition-of-satisfaction C
fields over the floor (1 cm cells); one action field per EB over the turning
angle; one proximity-sensor field.  Every number is a field of SpaParams
(params.py): the original code's (shared/papers/dft-spa-data/parameters.md),
which the paper's Table 2 restates in part; where the two differ, docs/dft.md
says which we follow and why.

Field arrays are [j, i]: j counts cells northwards (y), i eastwards (x).
"""

from __future__ import annotations

import math

from agents.controllers.dft.fields import Architecture, Coupling, Field, Input
from agents.controllers.dft.params import Lateral, SpaParams

EBS = ("N", "S", "W", "E")
# Travel of each EB in cells (dj, di), and the heading (rad, CCW from east) its action field aims at.
TRAVEL = {"N": (1, 0), "S": (-1, 0), "W": (0, -1), "E": (0, 1)}
HEADING = {"N": math.pi / 2, "S": 3 * math.pi / 2, "W": math.pi, "E": 0.0}
OPPOSITE = {"N": "S", "S": "N", "W": "E", "E": "W"}
ORTHOGONAL = {"N": ("W", "E"), "S": ("W", "E"), "W": ("N", "S"), "E": ("N", "S")}
ANGLES = 100  # cells of the action and proximity fields over [-pi, pi)


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
