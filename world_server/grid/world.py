"""The authoritative grid world and its tick rules.

One tick (lock-step semantics, identical in every engine):

1. every agent perceives the start-of-tick world (`perceive`);
2. every agent's controller chooses one action;
3. the world applies the actions in agent-id order (`apply_actions`):
   mark writes merge by min (order-free, as UPDATE-VALUE only lowers marks);
   trail paints of one tick on one cell merge by max trail id (the newest
   trail wins) and replace what was there; an erase clears the cell only if it
   holds the erased colour and nobody painted it this tick; loads are served
   in agent-id order (the lower id is served first when two agents empty one
   cell); unloads count only at the base; moves into an obstacle or off the
   grid are rejected and counted.  Agents may share a cell (as in the paper);
4. pheromone (ant model only) diffuses and evaporates.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from world_server.grid.bodies import Bodies
from world_server.grid.face.layout import (
    A_DEPOSIT,
    A_LOAD,
    A_MARK,
    A_MOVE,
    A_TRAIL_ID,
    A_TRAIL_OP,
    A_UNLOAD,
    ACT_LEN,
    AT_BASE,
    BLOCKED,
    CARRY,
    COMPASS_DC,
    COMPASS_DR,
    DIR_DC,
    DIR_DR,
    MARK,
    MARK_NONE,
    N_DIRS,
    OBST,
    PERC_F_LEN,
    PERC_LEN,
    PHER,
    RES,
    TRAIL,
    TRAIL_ERASE,
    TRAIL_PAINT,
    new_perception,
)
from world_server.grid.params import PhysicsParams
from world_server.grid.scenario import Layout, Scenario
from world_server.grid.steering import waypoints
from world_server.persist import ARRAYS as PERSISTED

# Integer layers of the grid, stacked in one (N_LAYERS, H, W) array.
L_OBST = 0
L_MARK = 1
L_TRAIL = 2
L_PAINT_TICK = 3  # last tick the cell was painted (merge rule for paints)
L_RES = 4
L_BFS = 5  # ground truth: BFS distance from the base, -1 if unreachable
N_LAYERS = 6

# Counters kept by apply_actions.
C_DELIVERED = 0
C_EXPLORED = 1  # marked cells
C_OPTIMAL = 2  # reachable cells whose mark equals the BFS distance
C_REJECTED = 3  # moves into walls or off the grid
C_LOADS = 4
N_COUNTERS = 5

# World parameters (float64 vector).
W_QMAX = 0
W_DEPOSIT = 1
W_DIFFUSION = 2
W_EVAPORATION = 3
N_WPARAMS = 4


@njit(cache=True, inline="always")
def perceive(layers, pher, pher_on, base_r, base_c, r, c, payload, blocked, pi, pf):
    """Fill the perception of an agent at (r, c): its cell and 4 neighbours
    (pheromone only when pher_on: no other controller smells it)."""
    h = layers.shape[1]
    w = layers.shape[2]
    for k in range(5):
        rr = r
        cc = c
        if k > 0:
            rr = r + DIR_DR[k - 1]
            cc = c + DIR_DC[k - 1]
        if rr < 0 or rr >= h or cc < 0 or cc >= w or layers[L_OBST, rr, cc] != 0:
            pi[OBST + k] = 1
            pi[MARK + k] = MARK_NONE
            pi[TRAIL + k] = 0
            pi[RES + k] = 0
            pf[PHER + k] = 0.0
        else:
            pi[OBST + k] = 0
            pi[MARK + k] = layers[L_MARK, rr, cc]
            pi[TRAIL + k] = layers[L_TRAIL, rr, cc]
            pi[RES + k] = 1 if layers[L_RES, rr, cc] > 0 else 0
            pf[PHER + k] = pher[rr, cc] if pher_on else 0.0
    pi[AT_BASE] = 1 if (r == base_r and c == base_c) else 0
    pi[COMPASS_DR] = (base_r > r) - (base_r < r)
    pi[COMPASS_DC] = (base_c > c) - (base_c < c)
    pi[CARRY] = payload
    pi[BLOCKED] = blocked


@njit(cache=True, inline="always")
def write_mark(layers, r, c, value, counters):
    old = layers[L_MARK, r, c]
    if value >= old:
        return
    truth = layers[L_BFS, r, c]
    if old == MARK_NONE:
        counters[C_EXPLORED] += 1
    if old == truth:
        counters[C_OPTIMAL] -= 1
    if value == truth:
        counters[C_OPTIMAL] += 1
    layers[L_MARK, r, c] = value


@njit(cache=True)
def apply_actions(layers, pher, base_r, base_c, pos, payload, acts, tick, wparams, counters):
    """Apply every agent's action for `tick`, in agent-id order (module doc)."""
    h = layers.shape[1]
    w = layers.shape[2]
    qmax = np.int64(wparams[W_QMAX])
    for a in range(pos.shape[0]):
        r = pos[a, 0]
        c = pos[a, 1]
        act = acts[a]
        write_mark(layers, r, c, act[A_MARK], counters)
        op = act[A_TRAIL_OP]
        if op == TRAIL_PAINT and not (r == base_r and c == base_c):
            if layers[L_PAINT_TICK, r, c] == tick:
                layers[L_TRAIL, r, c] = max(layers[L_TRAIL, r, c], act[A_TRAIL_ID])
            else:
                layers[L_TRAIL, r, c] = act[A_TRAIL_ID]
                layers[L_PAINT_TICK, r, c] = tick
        elif op == TRAIL_ERASE:
            if layers[L_PAINT_TICK, r, c] != tick and layers[L_TRAIL, r, c] == act[A_TRAIL_ID]:
                layers[L_TRAIL, r, c] = 0
        if act[A_LOAD] != 0 and layers[L_RES, r, c] > 0 and payload[a] < qmax:
            amount = min(qmax - payload[a], layers[L_RES, r, c])
            layers[L_RES, r, c] -= amount
            payload[a] += amount
            counters[C_LOADS] += 1
        if act[A_UNLOAD] != 0 and r == base_r and c == base_c:
            counters[C_DELIVERED] += payload[a]
            payload[a] = 0
        if act[A_DEPOSIT] != 0:
            pher[r, c] += wparams[W_DEPOSIT]
        d = act[A_MOVE]
        if 0 <= d < N_DIRS:
            nr = r + DIR_DR[d]
            nc = c + DIR_DC[d]
            if 0 <= nr < h and 0 <= nc < w and layers[L_OBST, nr, nc] == 0:
                pos[a, 0] = nr
                pos[a, 1] = nc
            else:
                counters[C_REJECTED] += 1


@njit(cache=True)
def diffuse_evaporate(pher, obst, diffusion, evaporation, out):
    """Each free cell keeps (1 - diffusion) of its pheromone and gives
    diffusion/4 to each neighbour; shares aimed at walls or off the grid stay
    home.  Then everything evaporates by `evaporation`.  Result in `pher`."""
    h, w = pher.shape
    share = diffusion / 4.0
    keep = 1.0 - evaporation
    for r in range(h):
        for c in range(w):
            if obst[r, c] != 0:
                out[r, c] = 0.0
                continue
            p = pher[r, c]
            total = (1.0 - diffusion) * p
            for k in range(N_DIRS):
                nr = r + DIR_DR[k]
                nc = c + DIR_DC[k]
                if 0 <= nr < h and 0 <= nc < w and obst[nr, nc] == 0:
                    total += share * pher[nr, nc]
                else:
                    total += share * p
            out[r, c] = total * keep
    pher[:, :] = out


@njit(cache=True, inline="always")
def resolve_tick(layers, pher, pher_scratch, base_r, base_c, pos, payload, acts, tick, wparams, counters, pher_on):
    """Steps 3 and 4 of the tick: apply every action, then let pheromone spread."""
    apply_actions(layers, pher, base_r, base_c, pos, payload, acts, tick, wparams, counters)
    if pher_on:
        diffuse_evaporate(pher, layers[L_OBST], wparams[W_DIFFUSION], wparams[W_EVAPORATION], pher_scratch)


class GridWorld:
    """The grid's state: layers, pheromone, agents' positions and payloads.
    It keeps world_server.contract.World (`until` says what `done` means)."""

    kind = "grid"
    SNAPSHOT = PERSISTED

    def __init__(self, scenario: Scenario, layout: Layout | None = None, until: str = "foraged"):
        layout = layout if layout is not None else scenario.layout()
        h, w = layout.shape
        self.scenario = scenario
        self.layout = layout
        self.base = layout.base
        self.layers = np.zeros((N_LAYERS, h, w), dtype=np.int64)
        self.layers[L_OBST] = layout.obstacles
        self.layers[L_MARK] = MARK_NONE
        self.layers[L_MARK][layout.base] = 0
        self.layers[L_PAINT_TICK] = -1
        self.layers[L_RES] = layout.resources
        self.layers[L_BFS] = layout.bfs
        self.pher = np.zeros((h, w), dtype=np.float64)
        self.pher_scratch = np.zeros((h, w), dtype=np.float64)
        n = scenario.agents
        self.pos = np.tile(np.array(layout.base, dtype=np.int64), (n, 1))
        self.payload = np.zeros(n, dtype=np.int64)
        self.blocked = np.zeros(n, dtype=np.int64)  # 1: the agent's last move did not happen (physical)
        self.acts = np.zeros((n, ACT_LEN), dtype=np.int64)
        self.counters = np.zeros(N_COUNTERS, dtype=np.int64)
        self.counters[C_EXPLORED] = 1
        self.counters[C_OPTIMAL] = 1
        self.total = int(layout.resources.sum())
        self.reachable = layout.reachable_cells
        a = scenario.ant
        self.wparams = np.array([scenario.q_max, a.deposit, a.diffusion, a.evaporation], dtype=np.float64)
        self.pheromone_on = scenario.controller == "ant"  # only ants lay pheromone
        self.bodies = Bodies(scenario.physics, layout.obstacles, n, layout.base)
        self.n, self.tick, self.until = n, 0, until

    # ------------------------------------------------------------- contract

    def perceive_all(self) -> tuple[np.ndarray, np.ndarray]:
        pi = np.zeros((self.n, PERC_LEN), np.int64)
        pf = np.zeros((self.n, PERC_F_LEN), np.float64)
        for a in range(self.n):
            self.perceive(a, pi[a], pf[a])
        return pi, pf

    def apply_all(self, actions: np.ndarray) -> None:
        self.acts[:] = actions
        self.resolve(self.tick)
        self.tick += 1

    def done(self) -> bool:
        foraged = int(self.counters[C_DELIVERED]) >= self.total
        converged = int(self.counters[C_OPTIMAL]) == self.reachable
        return {"foraged": foraged, "converged": converged, "both": foraged and converged}[self.until]

    def snapshot(self) -> dict[str, np.ndarray]:
        return {**{k: getattr(self, k).copy() for k in self.SNAPSHOT}, "body_xy": self.body_xy.copy(),
                "tick": np.array(self.tick)}  # fmt: skip

    def restore(self, state: dict[str, np.ndarray]) -> None:
        for k in self.SNAPSHOT:
            getattr(self, k)[...] = state[k]
        self.bodies.place(state["body_xy"])
        self.tick = int(state["tick"])

    # ------------------------------------------------------------------ parts

    def perceive(self, agent: int, pi: np.ndarray, pf: np.ndarray) -> None:
        r, c = self.pos[agent]
        perceive(self.layers, self.pher, self.pheromone_on, self.base[0], self.base[1], r, c, self.payload[agent],
                 self.blocked[agent], pi, pf)  # fmt: skip

    def resolve(self, tick: int) -> None:
        """Move the bodies (physical: only arrived moves count), apply the
        actions in `acts` for `tick` (agent-id order), then spread pheromone."""
        self.blocked[:] = self.bodies.move(self.pos, self.acts)
        resolve_tick(self.layers, self.pher, self.pher_scratch, self.base[0], self.base[1], self.pos, self.payload,
                     self.acts, tick, self.wparams, self.counters, self.pheromone_on)  # fmt: skip

    def warm_up(self) -> None:
        """Load the compiled tick kernels now (on scratch copies), so the first
        tick of a served run is not charged for it."""
        scratch = GridWorld.__new__(GridWorld)
        scratch.__dict__ = {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in self.__dict__.items()}
        scratch.bodies = Bodies(PhysicsParams(), self.layout.obstacles, 0, self.base)  # ideal: no simulation
        pi, pf = new_perception()
        if len(scratch.pos):
            scratch.perceive(0, pi, pf)
        scratch.resolve(-1)
        # and the physical bodies' steering, compiled on its own
        waypoints(np.zeros((1, 2)), np.zeros((1, 2), np.int64), np.asarray(self.layout.obstacles, dtype=bool),
                  np.zeros((1, 2)))  # fmt: skip

    def drop_load(self, agent: int) -> None:
        """A lost robot's cargo falls on its cell and becomes resource there
        (on the base it counts as delivered), so the run can still finish."""
        r, c = (int(v) for v in self.pos[agent])
        if (r, c) == self.base:
            self.counters[C_DELIVERED] += self.payload[agent]
        else:
            self.layers[L_RES, r, c] += self.payload[agent]
        self.payload[agent] = 0

    def new_body(self, agent: int) -> None:
        """A fresh body at the base, empty-handed, for an agent taking over a slot."""
        self.pos[agent] = self.base
        self.payload[agent] = 0
        self.blocked[agent] = 0
        self.bodies.reset(agent)

    def remove_body(self, agent: int) -> None:
        """A lost robot's body leaves the plane (it no longer blocks anyone)."""
        self.bodies.remove(agent)

    @property
    def body_xy(self) -> np.ndarray:
        """Every body's (x, y) in cells (cell centres under ideal physics)."""
        return self.bodies.positions(self.pos)

    @property
    def marks(self) -> np.ndarray:
        return self.layers[L_MARK]

    @property
    def trails(self) -> np.ndarray:
        return self.layers[L_TRAIL]

    @property
    def resources(self) -> np.ndarray:
        return self.layers[L_RES]

    @property
    def delivered(self) -> int:
        return int(self.counters[C_DELIVERED])

    @property
    def in_transit(self) -> int:
        return int(self.payload.sum())

    def apf_optimal(self) -> bool:
        return int(self.counters[C_OPTIMAL]) == self.reachable


# When a grid run ends: every unit delivered, marks equal to the BFS distance everywhere, or both.
UNTIL_FORAGED = 0
UNTIL_CONVERGED = 1
UNTIL_BOTH = 2
UNTIL = {"foraged": UNTIL_FORAGED, "converged": UNTIL_CONVERGED, "both": UNTIL_BOTH}


@njit(cache=True)
def is_done(until, counters, total, reachable):
    foraged = counters[C_DELIVERED] >= total
    converged = counters[C_OPTIMAL] == reachable
    if until == UNTIL_FORAGED:
        return foraged
    if until == UNTIL_CONVERGED:
        return converged
    return foraged and converged
