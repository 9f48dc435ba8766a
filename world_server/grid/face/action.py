"""What makes an action row one the world takes: shared by the world's check of every action
message and by the check of a user's step (agents.controllers.grid.dispatch.own_step), so a step
that answers out of range fails alike in both runtimes."""

from numba import njit

from world_server.grid.face.layout import (
    A_DEPOSIT,
    A_LOAD,
    A_MODE,
    A_MOVE,
    A_TRAIL_ID,
    A_TRAIL_OP,
    A_UNLOAD,
    N_MODES,
    STAY,
    TRAIL_ERASE,
)

# Fault codes (index of world_server.grid.face.own.FAULTS); the mark's is the last.
F_MOVE, F_TRAIL_OP, F_TRAIL_ID, F_LOAD, F_UNLOAD, F_DEPOSIT, F_MODE, F_MARK = range(8)


@njit(cache=True, inline="always")
def action_fault(act):
    """The first field of `act` out of its range (a fault code), or -1 when every field is in range."""
    if not 0 <= act[A_MOVE] <= STAY:
        return F_MOVE
    if not 0 <= act[A_TRAIL_OP] <= TRAIL_ERASE:
        return F_TRAIL_OP
    if act[A_TRAIL_ID] < 0:
        return F_TRAIL_ID
    if act[A_LOAD] != 0 and act[A_LOAD] != 1:
        return F_LOAD
    if act[A_UNLOAD] != 0 and act[A_UNLOAD] != 1:
        return F_UNLOAD
    if act[A_DEPOSIT] != 0 and act[A_DEPOSIT] != 1:
        return F_DEPOSIT
    if not 0 <= act[A_MODE] < N_MODES:
        return F_MODE
    return -1
