"""The grid controllers' contract: what a robot perceives, remembers and does.

Everything is a flat int64/float64 array so the same compiled step runs inside
the in-process engine's loop and, one agent at a time, inside an agent process.

Perception (what the paper's robot senses, never coordinates): the current cell
(index 0) and its four neighbours N, E, S, W (indices 1..4):

    OBST+k   1 if cell k is an obstacle or off the grid
    MARK+k   the integer mark of cell k (MARK_NONE when unmarked)
    TRAIL+k  the trail colour of cell k (0 = default colour, no trail)
    RES+k    1 if cell k holds resource
    AT_BASE  1 if the current cell is the base
    COMPASS_DR, COMPASS_DC  sign (-1, 0, 1) of the base's direction (ants only)
    CARRY    units of resource the robot carries (its payload sensor)
    BLOCKED  1 if the robot's last move did not happen (physical bodies that
             did not reach the cell in time; its odometry tells it so)

Float perception: PHER+k, the pheromone on cell k (ants only).

Action (one per tick; the world applies it, see world_server.grid.world):

    A_MOVE      0..3 = N, E, S, W; STAY = 4
    A_MARK      value to min-merge into the current cell (MARK_NONE = no write)
    A_TRAIL_OP  TRAIL_KEEP / TRAIL_PAINT / TRAIL_ERASE on the current cell
    A_TRAIL_ID  the colour painted, or the colour erased
    A_LOAD      1: pick up resource from the current cell
    A_UNLOAD    1: drop the payload (only counts at the base)
    A_DEPOSIT   1: drop pheromone on the current cell (ants only)
    A_MODE      the controller's mode after this step (MODE_NAMES), for the
                record only: the world never acts on it
"""

import numpy as np

N_DIRS = 4
STAY = 4
# Row/column offsets of N, E, S, W (rows grow downwards).
DIR_DR = np.array([-1, 0, 1, 0], dtype=np.int64)
DIR_DC = np.array([0, 1, 0, -1], dtype=np.int64)
DIR_NAMES = ("N", "E", "S", "W")

MARK_NONE = np.int64(2**62)

OBST = 0
MARK = 5
TRAIL = 10
RES = 15
AT_BASE = 20
COMPASS_DR = 21
COMPASS_DC = 22
CARRY = 23
BLOCKED = 24
PERC_LEN = 25

PHER = 0
PERC_F_LEN = 5

A_MOVE = 0
A_MARK = 1
A_TRAIL_OP = 2
A_TRAIL_ID = 3
A_LOAD = 4
A_UNLOAD = 5
A_DEPOSIT = 6
A_MODE = 7
ACT_LEN = 8

TRAIL_KEEP = 0
TRAIL_PAINT = 1
TRAIL_ERASE = 2

# Agent memory (int64 words kept between ticks by whoever runs the controller).
M_MODE = 0
M_PREV = 1  # direction of the cell the agent came from, -1 if none
M_TRAIL = 2  # colour being laid, removed or erased
M_CLIMB_MAX = 3  # highest mark seen on the current climb
M_CLIMB_STALL = 4  # climb steps since that maximum last rose
M_CLIMBING = 5  # 1 if the last move was a climb along a trail
M_LOADING = 6  # 1 if the last action was LOAD (the outcome is read this tick)
M_DETOUR = 7  # ants: random steps left after the compass way home was blocked
M_HEADING = M_CLIMB_MAX  # ants (which never climb a trail): heading + 1 in degrees clockwise from north, 0 unset
MEM_LEN = 8

# Controller modes (shared names so the recorder can label them).
SEARCH = 0
RETURN = 1  # plain descent to the base
RETURN_COLOUR = 2
RETURN_REMOVE = 3
ERASE = 4  # wiping a trail fragment that leads nowhere (not carrying)
RETURN_MEND = 5  # home along an existing trail, colouring its gaps
MODE_NAMES = ("searching", "returning", "colouring", "removing", "erasing", "mending")
N_MODES = len(MODE_NAMES)


# Controller kinds (the first argument of dispatch.step_controller).
MARKING = 0
CMARKING = 1
ANT = 2
CONTROLLERS: dict[str, int] = {"cmarking": CMARKING, "marking": MARKING, "ant": ANT}
N_PARAMS = 4  # length of the controllers' float parameter vector (the world sends it in the welcome)
P_CLIMB_PATIENCE = 0  # cmarking: ticks a climber may stall on a trail before it erases it ([cmarking])
P_DESCEND_ON_TRAIL = 1  # cmarking: 1 when a returner that loaded on a trail descends without colouring (rule 5)
P_FORGET_AT_BASE = 2  # cmarking: 1 when an agent forgets the cell it came from once it unloads (rule 6)
P_THRESHOLD = 0  # ant: the pheromone an ant follows ([ant])
P_DETOUR = 1  # ant: ticks of random walk after losing the pheromone ([ant])
P_WIGGLE = 2  # ant: its heading turns by up to this many degrees each way every step ([ant])
P_CEILING = 3  # ant: it sniffs for a stronger scent only below this pheromone on its cell ([ant])


def controller_kind(name: str) -> int:
    try:
        return CONTROLLERS[name]
    except KeyError:
        raise ValueError(f"unknown controller {name!r}: choose one of {', '.join(CONTROLLERS)}") from None


def controller_params(scenario) -> np.ndarray:
    """The float parameter vector of a grid scenario's controller (its [cmarking] or [ant] table)."""
    params = np.zeros(N_PARAMS, dtype=np.float64)
    if scenario.controller == "cmarking":
        params[P_CLIMB_PATIENCE] = scenario.cmarking.climb_patience
        params[P_DESCEND_ON_TRAIL] = scenario.cmarking.return_on_trail == "descend"
        params[P_FORGET_AT_BASE] = scenario.cmarking.at_base == "forget"
    elif scenario.controller == "ant":
        params[P_THRESHOLD] = scenario.ant.threshold
        params[P_DETOUR] = scenario.ant.detour
        params[P_WIGGLE] = scenario.ant.wiggle
        params[P_CEILING] = scenario.ant.ceiling
    return params


def new_perception() -> tuple[np.ndarray, np.ndarray]:
    return np.zeros(PERC_LEN, dtype=np.int64), np.zeros(PERC_F_LEN, dtype=np.float64)


def new_action() -> np.ndarray:
    return np.zeros(ACT_LEN, dtype=np.int64)


def new_memory(n: int = 1) -> np.ndarray:
    mem = np.zeros((n, MEM_LEN), dtype=np.int64)
    mem[:, M_PREV] = -1
    return mem
