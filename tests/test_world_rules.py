"""The tick's conflict rules (world_server.grid.world): loads in id order, paint and
erase merges, min-merged marks, rejected moves, unloads only at the base."""

import numpy as np

from swarm.engines.grid import Engine
from tests.helpers import ascii_scenario
from world_server.grid.face.layout import (
    A_LOAD,
    A_MARK,
    A_MOVE,
    A_TRAIL_ID,
    A_TRAIL_OP,
    A_UNLOAD,
    MARK_NONE,
    STAY,
    TRAIL_ERASE,
    TRAIL_PAINT,
)
from world_server.grid.world import C_DELIVERED, C_REJECTED, L_MARK, L_RES, L_TRAIL, apply_actions

ROWS = ["#####", "#B.R#", "#####"]


def _world(agents=2, quantity=150):
    engine = Engine(ascii_scenario(ROWS, agents=agents, quantity=quantity, q_max=100))
    w = engine.world
    w.acts[:] = 0
    w.acts[:, A_MOVE] = STAY
    w.acts[:, A_MARK] = MARK_NONE
    return w


def _apply(w, tick=0):
    apply_actions(w.layers, w.pher, w.base[0], w.base[1], w.pos, w.payload, w.acts, tick, w.wparams, w.counters)


def test_two_agents_loading_one_cell_are_served_in_id_order():
    w = _world(quantity=150)
    w.pos[:] = (1, 3)
    w.acts[:, A_LOAD] = 1
    _apply(w)
    assert list(w.payload) == [100, 50]
    assert w.layers[L_RES, 1, 3] == 0


def test_marks_merge_by_min_in_any_order():
    for order in ([5, 3], [3, 5]):
        w = _world()
        w.pos[:] = (1, 2)
        w.acts[:, A_MARK] = order
        _apply(w)
        assert w.layers[L_MARK, 1, 2] == 3


def test_paints_of_one_tick_keep_the_newest_trail_and_erase_yields():
    w = _world()
    w.pos[:] = (1, 2)
    w.acts[:, A_TRAIL_OP] = TRAIL_PAINT
    w.acts[:, A_TRAIL_ID] = [7, 9]
    _apply(w, tick=1)
    assert w.layers[L_TRAIL, 1, 2] == 9
    # an erase of another colour does nothing; of this colour, in the same tick as a paint, loses
    w.acts[0, A_TRAIL_OP], w.acts[0, A_TRAIL_ID] = TRAIL_ERASE, 9
    w.acts[1, A_TRAIL_OP], w.acts[1, A_TRAIL_ID] = TRAIL_PAINT, 4
    _apply(w, tick=2)
    assert w.layers[L_TRAIL, 1, 2] == 4
    w.acts[1, A_TRAIL_OP] = 0
    w.acts[0, A_TRAIL_ID] = 4
    _apply(w, tick=3)
    assert w.layers[L_TRAIL, 1, 2] == 0


def test_moves_into_walls_are_rejected_and_counted():
    w = _world(agents=1)
    w.acts[0, A_MOVE] = 0  # north of the base is a wall
    _apply(w)
    assert tuple(w.pos[0]) == w.base and w.counters[C_REJECTED] == 1


def test_unload_counts_only_at_the_base():
    w = _world(agents=1)
    w.payload[0] = 100
    w.pos[0] = (1, 2)
    w.acts[0, A_UNLOAD] = 1
    _apply(w)
    assert w.counters[C_DELIVERED] == 0 and w.payload[0] == 100
    w.pos[0] = w.base
    _apply(w)
    assert w.counters[C_DELIVERED] == 100 and w.payload[0] == 0


def test_pheromone_diffusion_conserves_mass_without_evaporation():
    from world_server.grid.world import diffuse_evaporate

    obst = np.zeros((6, 7), dtype=np.int64)
    obst[2, 3] = 1
    pher = np.zeros((6, 7))
    pher[0, 0], pher[3, 3] = 10.0, 5.0
    out = np.empty_like(pher)
    for _ in range(50):
        diffuse_evaporate(pher, obst, 0.95, 0.0, out)
    assert abs(pher.sum() - 15.0) < 1e-9 and pher[2, 3] == 0.0
    diffuse_evaporate(pher, obst, 0.95, 0.005, out)
    assert abs(pher.sum() - 15.0 * 0.995) < 1e-9
