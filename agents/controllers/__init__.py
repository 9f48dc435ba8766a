"""Grid controllers and the one dispatch both engines call.

`step_controller(kind, ...)` is compiled once; the in-process engine calls it
in its loop over agents and an agent process calls it for its single agent,
so there is exactly one implementation of every controller's step.
"""

import numpy as np
from numba import njit

from agents.controllers.ant import (
    DEFAULT_DETOUR,
    DEFAULT_THRESHOLD,
    P_DETOUR,
    P_THRESHOLD,
    ant_step,
)
from agents.controllers.cmarking import DEFAULT_CLIMB_PATIENCE, P_CLIMB_PATIENCE, cmarking_step
from agents.controllers.marking import marking_step

MARKING = 0
CMARKING = 1
ANT = 2
CONTROLLERS: dict[str, int] = {"marking": MARKING, "cmarking": CMARKING, "ant": ANT}
N_PARAMS = 4


@njit(cache=True)
def step_controller(kind, pi, pf, mem, act, params, seed, agent, tick):
    if kind == CMARKING:
        cmarking_step(pi, pf, mem, act, params, seed, agent, tick)
    elif kind == MARKING:
        marking_step(pi, pf, mem, act, params, seed, agent, tick)
    else:
        ant_step(pi, pf, mem, act, params, seed, agent, tick)


def controller_kind(name: str) -> int:
    try:
        return CONTROLLERS[name]
    except KeyError:
        raise ValueError(f"unknown controller {name!r}: choose one of {', '.join(CONTROLLERS)}") from None


def controller_params(name: str, cmarking: dict | None = None, ant: dict | None = None) -> np.ndarray:
    """The float parameter vector of a controller, defaults filled in."""
    params = np.zeros(N_PARAMS, dtype=np.float64)
    if name == "cmarking":
        params[P_CLIMB_PATIENCE] = (cmarking or {}).get("climb_patience", DEFAULT_CLIMB_PATIENCE)
    elif name == "ant":
        params[P_THRESHOLD] = (ant or {}).get("threshold", DEFAULT_THRESHOLD)
        params[P_DETOUR] = (ant or {}).get("detour", DEFAULT_DETOUR)
    return params
