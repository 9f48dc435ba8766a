"""`marking`: the paper's Algorithms 2 and 3 (EXPLORATION & APF CONSTRUCTION,
SEARCH & RETURN TO BASE).  No trails: resources are found by exploration
alone and carried home by descending the marks."""

from numba import njit

from agents.controllers.grid.foraging import read_load_outcome, seek_resource, unload_if_home
from agents.controllers.grid.moves import descent_dir, explore_dir, opposite, reset_action
from world_server.grid.face.layout import A_MARK, A_MOVE, M_MODE, M_PREV, RETURN
from world_server.grid.face.marks import update_value


@njit(cache=True)
def marking_step(pi, pf, mem, act, params, seed, agent, tick):
    reset_action(act)
    act[A_MARK] = update_value(pi)
    read_load_outcome(pi, mem)
    if mem[M_MODE] == RETURN:
        if not unload_if_home(pi, mem, act):
            act[A_MOVE] = descent_dir(pi, seed, agent, tick, 1)
            return
    if seek_resource(pi, mem, act, seed, agent, tick):
        return
    d = explore_dir(pi, seed, agent, tick, 2)
    act[A_MOVE] = d
    mem[M_PREV] = opposite(d) if d < 4 else -1
