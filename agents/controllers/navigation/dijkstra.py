"""Shortest routes from one node over a small weighted digraph, compiled.

The BG animat asks its map for routes to what its places hold each time the
map changes (an observation every 0.3 m).  scipy.sparse.csgraph.dijkstra
answers the same, but spends some 50 microseconds building and checking a
sparse matrix for a graph of a few dozen nodes, and brings scipy.sparse into
the agent process.  This is plain Dijkstra with a binary heap: a node is
settled once, a route is replaced only by a strictly shorter one (so among
equally long routes the first found stays), distances are summed along the
route from the source, as scipy sums them.
"""

from __future__ import annotations

import numpy as np

from swarm.core.kernels import exported, njit

NO_NODE = -9999  # the predecessor of the source and of unreachable nodes (scipy's value)


def shortest_routes(nodes: int, source: int, heads: np.ndarray, tails: np.ndarray,
                    lengths: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """(distance, predecessor) of every node from `source` over the edges heads[e] -> tails[e] of
    non-negative `lengths`; inf and NO_NODE where no route reaches."""
    dist, pred = np.empty(nodes), np.empty(nodes, np.int64)
    _dijkstra(source, np.ascontiguousarray(heads, np.int64), np.ascontiguousarray(tails, np.int64),
              np.ascontiguousarray(lengths, np.float64), dist, pred)  # fmt: skip
    return dist, pred


@njit(cache=True, inline="always")
def _before(d: float, v: int, other_d: float, other_v: int) -> bool:
    """Heap order: by distance, then by node."""
    return d < other_d or (d == other_d and v < other_v)


@exported("dijkstra", "void(int64, int64[::1], int64[::1], float64[::1], float64[::1], int64[::1])")
@njit(cache=True)
def _dijkstra(source: int, heads: np.ndarray, tails: np.ndarray, lengths: np.ndarray, dist: np.ndarray,
              pred: np.ndarray) -> None:  # fmt: skip
    n, m = dist.shape[0], heads.shape[0]
    start = np.zeros(n + 1, np.int64)  # the edges grouped by head, each head's in their given order
    for e in range(m):
        start[heads[e] + 1] += 1
    for v in range(n):
        start[v + 1] += start[v]
    order, fill = np.empty(m, np.int64), start[:n].copy()
    for e in range(m):
        order[fill[heads[e]]] = e
        fill[heads[e]] += 1
    dist[:] = np.inf
    pred[:] = NO_NODE
    done = np.zeros(n, np.bool_)
    heap_d, heap_v = np.empty(m + 1), np.empty(m + 1, np.int64)  # a binary heap of (distance, node), stale kept
    size = 1
    heap_d[0], heap_v[0] = 0.0, source
    dist[source] = 0.0
    while size > 0:
        d, u = heap_d[0], heap_v[0]
        size -= 1  # pop: the last entry sinks from the root
        last_d, last_v, i = heap_d[size], heap_v[size], 0
        while True:
            c = 2 * i + 1
            if c >= size:
                break
            if c + 1 < size and _before(heap_d[c + 1], heap_v[c + 1], heap_d[c], heap_v[c]):
                c += 1
            if _before(heap_d[c], heap_v[c], last_d, last_v):
                heap_d[i], heap_v[i] = heap_d[c], heap_v[c]
                i = c
            else:
                break
        heap_d[i], heap_v[i] = last_d, last_v
        if done[u]:
            continue
        done[u] = True
        for q in range(start[u], start[u + 1]):
            e = order[q]
            v = tails[e]
            nd = d + lengths[e]
            if not done[v] and nd < dist[v]:
                dist[v], pred[v] = nd, u
                i = size  # push: it rises from the end
                size += 1
                while i > 0:
                    p = (i - 1) // 2
                    if not _before(nd, v, heap_d[p], heap_v[p]):
                        break
                    heap_d[i], heap_v[i] = heap_d[p], heap_v[p]
                    i = p
                heap_d[i], heap_v[i] = nd, v
