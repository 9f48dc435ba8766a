"""c-marking's rules on hand-made perceptions (agents/controllers/grid/cmarking.py)."""

import numpy as np

from agents.controllers.grid.cmarking import new_trail_id
from agents.controllers.grid.dispatch import step_controller
from world_server.grid.face.layout import (
    A_LOAD,
    A_MARK,
    A_MOVE,
    A_TRAIL_ID,
    A_TRAIL_OP,
    BLOCKED,
    CARRY,
    CMARKING,
    ERASE,
    M_CLIMB_MAX,
    M_CLIMB_STALL,
    M_CLIMBING,
    M_LOADING,
    M_MODE,
    M_PREV,
    M_TRAIL,
    MARK,
    MARK_NONE,
    OBST,
    RES,
    RETURN_COLOUR,
    RETURN_MEND,
    RETURN_REMOVE,
    SEARCH,
    TRAIL,
    TRAIL_ERASE,
    TRAIL_PAINT,
    controller_params,
    new_action,
    new_memory,
    new_perception,
)
from world_server.grid.scenario import Scenario

N, E, S, W = 0, 1, 2, 3
PARAMS = controller_params(Scenario("rules", "test", controller="cmarking"))


def _perception(marks, trails=(0, 0, 0, 0, 0), res=(0, 0, 0, 0, 0), obst=(0, 0, 0, 0, 0), carry=0):
    pi, pf = new_perception()
    for k in range(5):
        pi[MARK + k], pi[TRAIL + k], pi[RES + k], pi[OBST + k] = marks[k], trails[k], res[k], obst[k]
    pi[CARRY] = carry
    return pi, pf


def _step(pi, pf, mem, tick=3, agent=0, seed=1):
    act = new_action()
    step_controller(CMARKING, pi, pf, mem, act, PARAMS, np.int64(seed), agent, tick)
    return act


X = MARK_NONE


def test_update_value_and_exploration_prefer_unmarked_cells():
    pi, pf = _perception([X, 4, X, 6, 5])
    for tick in range(20):
        mem = new_memory()[0]
        act = _step(pi, pf, mem, tick=tick)
        assert act[A_MARK] == 5 and act[A_MOVE] == E


def test_resource_in_view_is_entered_then_loaded():
    mem = new_memory()[0]
    act = _step(*_perception([3, 2, 4, 4, 4], res=(0, 0, 0, 1, 0)), mem)
    assert act[A_MOVE] == S
    act = _step(*_perception([4, 3, 5, 5, 5], res=(1, 0, 0, 0, 0)), mem)
    assert act[A_LOAD] == 1 and mem[M_LOADING] == 1


def test_loading_outcome_chooses_the_return():
    # resource left, uncoloured cell: colour a new trail, starting on this cell
    mem = new_memory()[0]
    mem[M_LOADING] = 1
    act = _step(*_perception([4, 3, 5, 5, 5], res=(1, 0, 0, 0, 0), carry=100), mem, tick=9, agent=2)
    assert mem[M_MODE] == RETURN_COLOUR and mem[M_TRAIL] == new_trail_id(9, 2)
    assert act[A_TRAIL_OP] == TRAIL_PAINT and act[A_MOVE] == N
    # exhausted, on a trail: remove that trail
    mem = new_memory()[0]
    mem[M_LOADING] = 1
    act = _step(*_perception([4, 3, 5, 5, 5], trails=(77, 77, 0, 0, 0), carry=100), mem)
    assert mem[M_MODE] == RETURN_REMOVE and act[A_TRAIL_OP] == TRAIL_ERASE and act[A_TRAIL_ID] == 77
    assert act[A_MOVE] == N
    # nothing was left for us: search again
    mem = new_memory()[0]
    mem[M_LOADING] = 1
    _step(*_perception([4, 3, 5, 5, 5]), mem)
    assert mem[M_MODE] == SEARCH


def test_climb_goes_to_the_highest_coloured_neighbour_but_not_back():
    mem = new_memory()[0]
    mem[M_PREV] = E
    act = _step(*_perception([5, 4, 6, 7, X], trails=(8, 8, 8, 0, 0)), mem)
    assert act[A_MOVE] == N or act[A_MOVE] == E  # E is the previous cell: never chosen
    assert act[A_MOVE] == N
    assert mem[M_CLIMBING] == 1


def test_a_blocked_climber_forgets_its_previous_cell_but_not_its_climb():
    # its last move (from E) did not happen, so E is not where it came from; the climb's
    # progress stays: it has seen mark 7 and stalled 3 steps, and this step stalls again
    mem = new_memory()[0]
    mem[M_CLIMBING], mem[M_PREV], mem[M_CLIMB_MAX], mem[M_CLIMB_STALL] = 1, E, 7, 3
    pi, pf = _perception([5, 4, 6, 7, X], trails=(8, 8, 8, 0, 0))
    pi[BLOCKED] = 1
    act = _step(pi, pf, mem)
    assert act[A_MOVE] == E  # the highest trail neighbour, no longer excluded
    assert mem[M_CLIMBING] == 1 and mem[M_CLIMB_MAX] == 7 and mem[M_CLIMB_STALL] == 4


def test_a_climb_that_ends_nowhere_erases_the_fragment():
    mem = new_memory()[0]
    mem[M_CLIMBING], mem[M_PREV] = 1, S
    act = _step(*_perception([9, 10, 10, 8, 10], trails=(5, 0, 0, 5, 0)), mem)
    assert mem[M_MODE] == ERASE and act[A_TRAIL_OP] == TRAIL_ERASE and act[A_TRAIL_ID] == 5
    assert act[A_MOVE] == S


def test_next_to_the_base_a_trail_end_is_not_a_dead_end():
    mem = new_memory()[0]
    mem[M_CLIMBING], mem[M_PREV] = 1, N
    _step(*_perception([1, 2, 2, 0, 2], trails=(5, 5, 0, 0, 0)), mem)
    assert mem[M_MODE] == SEARCH


def test_loading_on_a_trail_follows_it_home_and_mends_gaps():
    # resource left on a coloured cell: go home along the trail (S, mark 3 < 4), colour nothing here
    mem = new_memory()[0]
    mem[M_LOADING] = 1
    act = _step(*_perception([4, 5, 3, 3, 5], trails=(7, 0, 0, 7, 0), res=(1, 0, 0, 0, 0), carry=100), mem)
    assert mem[M_MODE] == RETURN_MEND and mem[M_TRAIL] == 7
    assert act[A_TRAIL_OP] == 0 and act[A_MOVE] == S  # E has the same mark but is not the trail
    # on an uncoloured cell (a gap in the trail): colour it, then descend the marks
    act = _step(*_perception([3, 2, 4, 4, 4]), mem)
    assert act[A_TRAIL_OP] == TRAIL_PAINT and act[A_TRAIL_ID] == 7 and act[A_MOVE] == N
    # a cell of another trail is left as it is
    act = _step(*_perception([2, 1, 3, 3, 3], trails=(9, 0, 0, 0, 0)), mem)
    assert act[A_TRAIL_OP] == 0 and act[A_MOVE] == N
