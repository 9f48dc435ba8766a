"""A user's grid controller whose step answers a move the world refuses: its run ends in one line."""

from numba import njit

from world_server.grid.face.layout import A_MARK, A_MOVE
from world_server.grid.face.own import GridController


@njit
def jump(pi, pf, mem, act, params, seed, agent, tick):
    if tick == 3:
        act[A_MOVE] = 9  # there are 5 moves


@njit
def scrawl(pi, pf, mem, act, params, seed, agent, tick):
    act[A_MARK] = -5  # lower than UPDATE-VALUE allows on any cell


@njit
def typo(pi, pf, mem, act, params, seed, agent, tick):
    act[A_MOVE] = pi.nothing  # does not compile


JUMPER = GridController(step=jump, description="jumps out of the grid at tick 3")
SCRAWLER = GridController(step=scrawl, description="writes a mark below UPDATE-VALUE")
TYPO = GridController(step=typo, description="does not compile")
NOT_A_GRID_CONTROLLER = 42
