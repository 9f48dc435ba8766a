"""The ant baseline, NetLogo's Ants model on the grid (agents/controllers/grid/ant.py), on hand-made
perceptions: a kept heading, uphill-chemical within the pheromone window, the wiggle, turning round."""

import numpy as np
import pytest

from agents.controllers.grid.ant import heading_dir, uphill_turn
from agents.controllers.grid.dispatch import step_controller
from world_server.grid.face.layout import (
    A_MOVE,
    ANT,
    M_HEADING,
    OBST,
    P_CEILING,
    P_THRESHOLD,
    P_WIGGLE,
    PHER,
    controller_params,
    new_action,
    new_memory,
    new_perception,
)
from world_server.grid.scenario import Scenario

N, E, S, W = 0, 1, 2, 3
PARAMS = controller_params(Scenario("ants", "test", controller="ant"))


def _step(pi, pf, mem, params=PARAMS, tick=3, agent=0, seed=1):
    act = new_action()
    step_controller(ANT, pi, pf, mem, act, params, np.int64(seed), agent, tick)
    return act


def _straight(**changes):
    params = PARAMS.copy()
    params[P_WIGGLE] = 0
    for key, value in changes.items():
        params[{"threshold": P_THRESHOLD, "ceiling": P_CEILING}[key]] = value
    return params


@pytest.mark.parametrize("heading, d", [(0, N), (44, N), (46, E), (90, E), (180, S), (270, W), (315, N), (359, N)])
def test_ahead_is_the_neighbour_nearest_the_heading(heading, d):
    assert heading_dir(heading) == d


def test_uphill_turns_45_degrees_towards_the_stronger_side_only_when_it_beats_ahead():
    pf = np.zeros(5)
    pf[PHER + 1 + N], pf[PHER + 1 + E], pf[PHER + 1 + W] = 0.1, 0.5, 0.2  # heading north: right is east
    assert uphill_turn(pf, 0) == 45
    pf[PHER + 1 + W] = 0.9
    assert uphill_turn(pf, 0) == 315
    pf[PHER + 1 + N] = 1.0
    assert uphill_turn(pf, 0) == 0


def test_without_wiggle_or_scent_an_ant_keeps_its_heading():
    pi, pf = new_perception()
    mem = new_memory()[0]
    mem[M_HEADING] = 90 + 1
    for tick in range(5):
        assert _step(pi, pf, mem, _straight(), tick=tick)[A_MOVE] == E
    assert mem[M_HEADING] == 91


def test_the_scent_turns_an_ant_only_inside_its_window():
    pi, pf = new_perception()
    pf[PHER], pf[PHER + 1 + E] = 0.5, 2.0  # heading north, east smells stronger
    mem = new_memory()[0]
    mem[M_HEADING] = 1
    _step(pi, pf, mem, _straight(threshold=0.1, ceiling=1.0))
    assert mem[M_HEADING] == 45 + 1  # turned 45 degrees: still nearest north
    mem[M_HEADING] = 1
    _step(pi, pf, mem, _straight(threshold=0.6, ceiling=1.0))  # its cell below the window: no sniffing
    assert mem[M_HEADING] == 1


def test_an_ant_facing_a_wall_turns_round():
    pi, pf = new_perception()
    pi[OBST + 1 + N] = 1
    mem = new_memory()[0]
    mem[M_HEADING] = 1
    assert _step(pi, pf, mem, _straight())[A_MOVE] == S and mem[M_HEADING] == 180 + 1


def test_the_wiggle_spreads_headings_within_its_width():
    pi, pf = new_perception()
    turns = []
    for tick in range(400):
        mem = new_memory()[0]
        mem[M_HEADING] = 180 + 1
        _step(pi, pf, mem, tick=tick)
        turns.append(int(mem[M_HEADING]) - 1 - 180)
    width = int(PARAMS[P_WIGGLE])
    assert max(turns) <= width - 1 and min(turns) >= -(width - 1) and np.std(turns) > width / 4
