"""Grid controllers and the one dispatch both engines call.

`step_controller(kind, ...)` is compiled once; the in-process engine calls it
in its loop over agents and an agent process calls it for its single agent,
so there is exactly one implementation of every controller's step.
"""

import numpy as np
from numba import njit

from agents.controllers.ant import (
    P_DETOUR,
    P_THRESHOLD,
    ant_step,
)
from agents.controllers.cmarking import P_CLIMB_PATIENCE, cmarking_step
from agents.controllers.layout import A_MODE, BLOCKED, CMARKING, M_MODE, M_PREV, MARKING, N_PARAMS
from agents.controllers.marking import marking_step
from swarm.scenario import Scenario


@njit(cache=True)
def step_controller(kind, pi, pf, mem, act, params, seed, agent, tick):
    if pi[BLOCKED] != 0:
        # The last move did not happen: forget where we "came from" (a cell we never
        # left).  The climb goes on: a climber stuck on a trail keeps counting towards
        # its patience, so a crowd held on a trail that leads nowhere erases it and
        # disperses (resetting the climb here made 80 robots jam; docs/physics.md).
        mem[M_PREV] = -1
    if kind == CMARKING:
        cmarking_step(pi, pf, mem, act, params, seed, agent, tick)
    elif kind == MARKING:
        marking_step(pi, pf, mem, act, params, seed, agent, tick)
    else:
        ant_step(pi, pf, mem, act, params, seed, agent, tick)
    act[A_MODE] = mem[M_MODE]  # reported for the recording


def warm_up() -> None:
    """Compile, or load from the cache, the step kernel now: an agent's first
    observation must not wait for it (lock-step deadlines are short)."""
    from agents.controllers.layout import new_action, new_memory, new_perception

    pi, pf = new_perception()
    step_controller(MARKING, pi, pf, new_memory(1)[0], new_action(), np.zeros(N_PARAMS), np.int64(0), 0, 0)


def controller_params(scenario: Scenario) -> np.ndarray:
    """The float parameter vector of the scenario's controller."""
    params = np.zeros(N_PARAMS, dtype=np.float64)
    if scenario.controller == "cmarking":
        params[P_CLIMB_PATIENCE] = scenario.cmarking.climb_patience
    elif scenario.controller == "ant":
        params[P_THRESHOLD] = scenario.ant.threshold
        params[P_DETOUR] = scenario.ant.detour
    return params
