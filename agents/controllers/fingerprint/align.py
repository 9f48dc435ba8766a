"""Global alignment with uncertainty (Tapus et al. 2004, after Needleman-Wunsch),
circular: the cost of turning one fingerprint into another, minimised over
the rotations of one of them, and a probability of matching from it.

The costs are negative log-probabilities of the events that make two views
of one place differ (our reading of "with uncertainty"; the constants are
ours, docs/fingerprint.md):
- a feature missed or spurious (a gap) costs -ln(p_miss) of its type: hue
  patches are seldom missed, edges and corners more often, an empty-space
  quantum `n` often gains or loses one;
- a hue patch read one bin off (lighting, the bin boundary) costs
  `hue_near`; any other substitution costs `wrong`, more than a gap of either
  feature, so one missing feature always costs less than one wrong one;
- identical features cost nothing.

Two kernels: `cyclic_cost_exact` tries every rotation (m global alignments;
the reference) and `cyclic_cost` does one pass over the node's string
written twice, each cell remembering where its path entered, a path allowed
to consume at most one turn of the node, the node's characters it left out
charged as gaps.  Each of its answers is the cost of a real alignment with a
real rotation, so it is never below the exact minimum; tests measure how
often it is above.  `localize` runs `cyclic_cost` against every node of a map
in one compiled call.
"""

from __future__ import annotations

import math

import numpy as np

from agents.controllers.fingerprint.params import AlignParams
from swarm.core.kernels import exported, njit

HUES = 16  # symbols 0..15: hue bins 'A'..'P'
V, C, N = 16, 17, 18  # vertical edge, laser corner; N + k - 1: a run of k empty-space quanta
MAX_RUN = 36
SYMBOLS = N + MAX_RUN
LETTERS = "ABCDEFGHIJKLMNOP" + "vc"
SCALE = 1000  # costs are integers in thousandths of a nat (exact sums, one integer per cell)
SHIFT = 12  # a DP cell is cost << SHIFT | the column where its path entered (strings up to 2047)
MAX_LENGTH = (1 << (SHIFT - 1)) - 1
MASK = (1 << SHIFT) - 1  # a cell's entry column
NEVER = 1 << 60  # a cell no path may take (more than one turn of the node)


def to_string(codes: np.ndarray) -> str:
    """The paper's notation: one `n` per empty-space quantum."""
    return "".join(LETTERS[c] if c < N else "n" * (c - N + 1) for c in (int(x) for x in codes))


def from_string(text: str) -> np.ndarray:
    """Symbols of a fingerprint written as the paper writes it (runs of `n` become one symbol)."""
    out: list[int] = []
    for ch in text:
        if ch == "n":
            if out and N <= out[-1] < SYMBOLS - 1:
                out[-1] += 1
            else:
                out.append(N)
        elif ch in LETTERS:
            out.append(LETTERS.index(ch))
        else:
            raise ValueError(f"fingerprint {text!r}: {ch!r} is not a feature; use A-P, v, c or n")
    return np.array(out, np.int8)


def cost_tables(p: AlignParams) -> tuple[np.ndarray, np.ndarray]:
    """(substitution costs SYMBOLS x SYMBOLS, gap cost per symbol), integers of SCALE.

    A run of k empty quanta is one symbol: it aligns with a run of l at the
    cost of |k - l| quanta gapped, and is gapped whole at k of them."""
    gap = np.empty(SYMBOLS)
    gap[:HUES] = -math.log(p.miss_hue)
    gap[V], gap[C] = -math.log(p.miss_edge), -math.log(p.miss_corner)
    runs = np.arange(1, MAX_RUN + 1)
    gap[N:] = runs * -math.log(p.miss_space)
    sub = np.full((SYMBOLS, SYMBOLS), p.wrong)
    for a in range(HUES):
        for b in range(HUES):
            ring = min(abs(a - b), HUES - abs(a - b))
            sub[a, b] = 0.0 if ring == 0 else (p.hue_near if ring == 1 else p.wrong)
    sub[V, V] = sub[C, C] = 0.0
    sub[N:, N:] = np.abs(runs[:, None] - runs[None, :]) * -math.log(p.miss_space)
    sub[N:, :N] = sub[:N, N:] = 1e6  # empty space is never a feature: always two gaps
    return np.round(sub * SCALE).astype(np.int64), np.round(gap * SCALE).astype(np.int64)


@njit(cache=True)
def _global(a, b, sub, gap):  # pragma: no cover - compiled
    n, m = len(a), len(b)
    row = np.empty(m + 1, np.int64)
    row[0] = 0
    for j in range(1, m + 1):
        row[j] = row[j - 1] + gap[b[j - 1]]
    for i in range(1, n + 1):
        diag = row[0]
        row[0] = diag + gap[a[i - 1]]
        ga = gap[a[i - 1]]
        for j in range(1, m + 1):
            up = row[j]
            best = min(up + ga, diag + sub[a[i - 1], b[j - 1]], row[j - 1] + gap[b[j - 1]])
            row[j] = best
            diag = up
    return row[m]


@exported("fp_cyclic_cost_exact", "int64(int8[:], int8[:], int64[:, :], int64[:])")
@njit(cache=True)
def cyclic_cost_exact(a, b, sub, gap):  # pragma: no cover - compiled
    """min over rotations r of the global alignment of a with b rotated by r."""
    m = len(b)
    if m == 0:
        return _global(a, b, sub, gap)
    bb = np.concatenate((b, b))
    best = _global(a, b, sub, gap)
    for r in range(1, m):
        best = min(best, _global(a, bb[r : r + m], sub, gap))
    return best


@njit(cache=True, inline="always")
def _load_node(codes, o, m, w, gap, cb, prefix, gb, row):  # pragma: no cover - compiled
    """The node codes[o:o+m] written twice over columns 1..w: its symbol (cb), gap (gb, shifted) and the
    gaps of the columns before (prefix); and the pass's first row, where a path enters the node's string
    at one of its m characters (a rotation)."""
    prefix[0] = 0
    for j in range(1, w + 1):
        c = codes[o + (j - 1) % m]
        cb[j] = c
        prefix[j] = prefix[j - 1] + gap[c]
        gb[j] = gap[c] << SHIFT
    for j in range(w + 1):
        row[j] = j if j < m else NEVER | j


@njit(cache=True, inline="always")
def _cell(up, diag, left, sub, gap, ga, j, m):  # pragma: no cover - compiled
    """One cell of the pass at column j: from above (a query symbol gapped, `ga`), the diagonal (a
    substitution, `sub`) or the left (a node symbol gapped, `gap`); a path may consume at most one turn
    of the node (j - its entry column <= m).  Both kernels' cells are this one."""
    best = up + ga
    s = diag + sub
    s = s if j - (diag & MASK) <= m else NEVER
    best = s if s < best else best
    h = left + gap
    h = h if j - (left & MASK) <= m else NEVER
    return h if h < best else best


@njit(cache=True)
def _cyclic(qsub, qgap, b, gap):  # pragma: no cover - compiled
    """The one-pass kernel for a query given as its rows of the substitution
    table and its gaps, both shifted (computed once per query, not per node)."""
    m = len(b)
    w = 2 * m
    tables = np.empty((4, w + 1), np.int64)
    cb, gb, prefix, row = tables[0], tables[1], tables[2], tables[3]
    _load_node(b, 0, m, w, gap, cb, prefix, gb, row)
    for i in range(len(qgap)):
        srow = qsub[i]
        ga = qgap[i]
        diag = row[0]
        left = diag + ga
        row[0] = left
        for j in range(1, w + 1):
            up = row[j]
            left = _cell(up, diag, left, srow[cb[j]], gb[j], ga, j, m)
            row[j] = left
            diag = up
    return _closed(row, prefix, m)


@njit(cache=True)
def _closed(row, prefix, m):  # pragma: no cover - compiled
    """The best cost in the last row of a pass over a node of m symbols written twice:
    a path that entered at column e and ends at j has left out the turn's characters j..e+m."""
    best = NEVER
    for j in range(2 * m + 1):
        end = (row[j] & MASK) + m
        if j <= end and end <= 2 * m:
            best = min(best, (row[j] >> SHIFT) + prefix[end] - prefix[j])
    return best


@exported("fp_cyclic_cost", "int64(int8[:], int8[:], int64[:, :], int64[:])")
@njit(cache=True)
def cyclic_cost(a, b, sub, gap):  # pragma: no cover - compiled
    """One pass over b written twice (see the module's docstring).  A cell holds
    cost << SHIFT | entry column, so one integer min keeps both (ties: the
    earlier entry), and no branch depends on the data."""
    if len(a) == 0 or len(b) == 0:
        return _global(a, b, sub, gap)
    qsub = np.empty((len(a), sub.shape[1]), np.int64)
    qgap = np.empty(len(a), np.int64)
    for i in range(len(a)):
        qsub[i] = sub[a[i]] << SHIFT
        qgap[i] = gap[a[i]] << SHIFT
    return _cyclic(qsub, qgap, b, gap)


LANES = 16  # nodes aligned side by side; a lane loop this long is one LLVM vectorizes (4 int64 per AVX2 register)


@njit(cache=True)
def _distinct(a):  # pragma: no cover - compiled
    """(the query's distinct symbols, and for each position its index among them)."""
    seen = np.full(SYMBOLS, -1, np.int64)
    symbols = np.empty(len(a), np.int64)
    rank = np.empty(len(a), np.int64)
    u = 0
    for i in range(len(a)):
        if seen[a[i]] < 0:
            seen[a[i]] = u
            symbols[u] = a[i]
            u += 1
        rank[i] = seen[a[i]]
    return symbols[:u], rank


@njit(cache=True)
def _load_lanes(codes, offsets, nodes, gap, m, cb, prefix, gb, row):  # pragma: no cover - compiled
    """Each lane's node (`_load_node`, a column of each table); the width is the longest lane's.  A
    shorter lane computes columns past its own width: no cell it reads later depends on them."""
    w = 2 * m.max()
    for lane in range(LANES):
        _load_node(codes, offsets[nodes[lane]], m[lane], w, gap, cb[:, lane], prefix[:, lane], gb[:, lane],
                   row[:, lane])  # fmt: skip
    return w


@njit(cache=True, inline="always")  # inlined, LLVM knows its rows are two arrays: 2.5x
def _lanes_pass(qgap, rank, tab, w, m, cb, gb, row, spare):  # pragma: no cover - compiled
    """`_cyclic`'s pass for LANES nodes at once: the lane loop has no dependency between its
    iterations (last row and this row are two arrays), so it compiles to vector instructions.
    Returns the array holding the last row."""
    cur, prev = spare, row
    for i in range(len(qgap)):
        ga = qgap[i]
        for lane in range(LANES):
            cur[0, lane] = prev[0, lane] + ga
        for j in range(1, w + 1):
            up, diag, left, here = prev[j], prev[j - 1], cur[j - 1], cur[j]
            sub, gj = tab[rank[i], j], gb[j]
            for lane in range(LANES):
                here[lane] = _cell(up[lane], diag[lane], left[lane], sub[lane], gj[lane], ga, j, m[lane])
        cur, prev = prev, cur
    return prev


@exported("fp_localize_costs", "int64[:](int8[:], int8[:], int64[:], int64[:, :], int64[:])")
@njit(cache=True)
def localize_costs(a, codes, offsets, sub, gap):  # pragma: no cover - compiled
    """cyclic_cost of `a` against every node k: codes[offsets[k]:offsets[k+1]].

    The same pass as `_cyclic`, cell for cell, run on LANES nodes side by side
    (nodes sorted by length, so a batch's lanes are about as wide): 4x the
    node-by-node kernel on AVX2.  A query symbol's substitution costs against
    a batch's columns are looked up once per distinct symbol, not per row."""
    k = len(offsets) - 1
    out = np.empty(k, np.int64)
    lengths = offsets[1:] - offsets[:-1]
    order = np.argsort(lengths, kind="mergesort")
    first = 0
    while first < k and (len(a) == 0 or lengths[order[first]] == 0):
        node = order[first]
        out[node] = _global(a, codes[offsets[node] : offsets[node + 1]], sub, gap)
        first += 1
    if first == k:
        return out
    symbols, rank = _distinct(a)
    qgap = np.empty(len(a), np.int64)
    for i in range(len(a)):
        qgap[i] = gap[a[i]] << SHIFT
    shape = (2 * lengths.max() + 1, LANES)
    cb, prefix, gb = np.zeros(shape, np.int64), np.zeros(shape, np.int64), np.empty(shape, np.int64)
    row, spare = np.empty(shape, np.int64), np.empty(shape, np.int64)
    tab = np.empty((len(symbols), shape[0], LANES), np.int64)
    nodes, m = np.empty(LANES, np.int64), np.empty(LANES, np.int64)
    for start in range(first, k, LANES):
        for lane in range(LANES):  # a last batch short of LANES repeats its last node
            nodes[lane] = order[min(start + lane, k - 1)]
            m[lane] = lengths[nodes[lane]]
        w = _load_lanes(codes, offsets, nodes, gap, m, cb, prefix, gb, row)
        for r in range(len(symbols)):
            srow = sub[symbols[r]]
            for j in range(1, w + 1):
                for lane in range(LANES):
                    tab[r, j, lane] = srow[cb[j, lane]] << SHIFT
        last = _lanes_pass(qgap, rank, tab, w, m, cb, gb, row, spare)
        for lane in range(min(LANES, k - start)):
            out[nodes[lane]] = _closed(last[:, lane], prefix[:, lane], m[lane])
    return out


def paper_length(codes: np.ndarray) -> int:
    """Length in the paper's characters (each empty quantum one `n`)."""
    c = np.asarray(codes, np.int64)
    return int(np.where(c >= N, c - N + 1, 1).sum())


class Matcher:
    """The alignment's costs and calibration, with the compiled kernels behind
    plain calls (int8 symbols in, costs in nats or probabilities out)."""

    def __init__(self, params: AlignParams | None = None):
        self.params = params or AlignParams()
        self.sub, self.gap = cost_tables(self.params)

    def cost(self, a: np.ndarray, b: np.ndarray, exact: bool = False) -> float:
        a, b = np.asarray(a, np.int8), np.asarray(b, np.int8)
        if max(len(a), len(b)) > MAX_LENGTH:
            raise ValueError(f"a fingerprint of {max(len(a), len(b))} symbols; at most {MAX_LENGTH} align")
        kernel = cyclic_cost_exact if exact else cyclic_cost
        return kernel(a, b, self.sub, self.gap) / SCALE

    def probability(self, a: np.ndarray, b: np.ndarray) -> float:
        return float(self.params.probability(self.cost(a, b), max(paper_length(a), paper_length(b))))

    def against(self, a: np.ndarray, codes: np.ndarray, offsets: np.ndarray, lengths: np.ndarray) -> np.ndarray:
        """P(match) of `a` with each of a packed set of strings (a map's nodes:
        node k is codes[offsets[k]:offsets[k + 1]], `lengths` in the paper's characters)."""
        a = np.asarray(a, np.int8)
        costs = localize_costs(a, codes, offsets, self.sub, self.gap) / SCALE
        return self.params.probability(costs, np.maximum(lengths, paper_length(a)))
