"""`swarm bench fingerprint`: what the fingerprint controller's parts cost on one core.

Real fingerprints: the scout drives the office floor's two tours and every
reading taken on the way is kept.  Rows: extracting a fingerprint (camera +
laser), one circular alignment (the one-pass kernel and the exact one that
tries every rotation), and localizing one fingerprint against maps of 20, 200
and 1000 nodes (real fingerprints as the nodes' means): the likelihood of
every node at every rotation in one compiled call (LANES nodes side by side,
align.localize_costs), and the whole Markov step
(prediction over the links, correction) on a map whose nodes are linked in a
chain with shortcuts.
"""

from __future__ import annotations

import time

import numpy as np

from agents.controllers.fingerprint.align import Matcher
from agents.controllers.fingerprint.features import Fingerprint, fingerprint
from agents.controllers.fingerprint.params import FeatureParams
from agents.controllers.fingerprint.signatures import FingerprintSignatures, pack
from agents.controllers.navigation.topomap import Link, Node, TopoMap

SIZES = (20, 200, 1000)
TARGET_MS = 10.0  # the target: one fingerprint against 1000 nodes, all rotations, on one core


def collect(every: int, quick: bool) -> tuple[list[dict], list[Fingerprint]]:
    """Readings (every `every` ticks) and the fingerprints of both office tours."""
    from swarm.engines.arena import ArenaEngine
    from swarm.experiments.tapus2006.fingerprint import tour_scenario

    readings, prints = [], []
    for route in ("mapping",) if quick else ("mapping", "localize"):
        engine = ArenaEngine(tour_scenario("office", route, "low", 0))
        c = engine.controllers[0]
        while not c.finished:
            if engine.tick % every == 0:
                readings.append(engine.world.perceive()[0])
            seen = len(c.log)
            engine.step(1)
            if len(c.log) > seen:
                prints.append(c.current)
    return readings, prints


def _per_call(fn, repeat: int) -> float:
    fn()
    best = []
    for _ in range(3):
        t = time.perf_counter()
        for _ in range(repeat):
            fn()
        best.append((time.perf_counter() - t) / repeat)
    return min(best)


def bench_fingerprint(quick: bool = False) -> dict:
    readings, prints = collect(10 if quick else 5, quick)
    p = FeatureParams()
    m = Matcher()
    out: dict = {"fingerprints": len(prints), "mean_symbols": round(float(np.mean([len(f.codes) for f in prints])), 1),
                 "mean_length": round(float(np.mean([f.length for f in prints])), 1)}  # fmt: skip
    k = 0

    def extract():
        nonlocal k
        r = readings[k % len(readings)]
        k += 1
        fingerprint(r["camera_rgb"], r["camera_range"], r["laser"], 8.0, p)

    out["features_ms"] = round(_per_call(extract, len(readings)) * 1e3, 3)
    rng = np.random.default_rng(0)
    pairs = [(prints[i].codes, prints[j].codes) for i, j in rng.integers(0, len(prints), (200, 2))]
    out["align_us"] = round(_per_call(lambda: [m.cost(a, b) for a, b in pairs], 3) / len(pairs) * 1e6, 2)
    out["align_exact_us"] = round(_per_call(lambda: [m.cost(a, b, exact=True) for a, b in pairs], 1) / len(pairs)
                                  * 1e6, 2)  # fmt: skip
    sig = FingerprintSignatures(m)
    rows = [_localize_row(size, prints, m, sig, rng) for size in (SIZES[:2] if quick else SIZES)]
    out["localize"] = rows
    return out


def _localize_row(size: int, prints: list[Fingerprint], m: Matcher, sig: FingerprintSignatures, rng) -> dict:
    """Localizing against `size` nodes (real fingerprints as their means)."""
    pick = rng.choice(len(prints), size, replace=size > len(prints))
    means = [prints[i] for i in pick]
    codes, offsets, lengths = pack([f.codes for f in means])
    queries = [prints[i] for i in rng.integers(0, len(prints), 20)]
    turn = iter(range(10**9))

    def likelihoods():
        m.against(queries[next(turn) % len(queries)].codes, codes, offsets, lengths)

    tm = TopoMap(sig)
    tm.nodes = [Node(f, [f], np.array([i * 0.5, 0.0])) for i, f in enumerate(means)]
    for i in range(size - 1):  # a chain, with a shortcut every seventh node
        tm.links[(i, i + 1)] = Link(np.array([0.5, 0.0]))
        if i + 5 < size and i % 7 == 0:
            tm.links[(i, i + 5)] = Link(np.array([2.5, 0.0]))

    def markov():
        tm.localize(queries[next(turn) % len(queries)], np.array([0.15, 0.0]))

    cells = sum(len(f.codes) for f in queries) / len(queries) * 2 * offsets[-1]
    t = _per_call(likelihoods, 10)
    return {"nodes": size, "likelihoods_ms": round(t * 1e3, 3), "markov_step_ms": round(_per_call(markov, 5) * 1e3, 3),
            "cells_per_s": round(cells / t)}  # fmt: skip


def format_fingerprint_bench(r: dict) -> str:
    lines = [f"fingerprint: {r['fingerprints']} real fingerprints from the office tours, {r['mean_length']} "
             f"characters ({r['mean_symbols']} symbols, a run of n as one) on average; one core",
             f"  features (camera 360 sectors + laser 360 beams): {r['features_ms']} ms per fingerprint",
             f"  one circular alignment: {r['align_us']} us (one pass); {r['align_exact_us']} us (every rotation)",
             "", "| nodes | likelihood of every node, all rotations | whole Markov step | DP cells/s |",
             "|---|---|---|---|"]  # fmt: skip
    for row in r["localize"]:
        lines.append(
            f"| {row['nodes']} | {row['likelihoods_ms']} ms | {row['markov_step_ms']} ms | {row['cells_per_s']:,} |"
        )
    lines.append(f"\ntarget: localizing one fingerprint against 1000 nodes (all rotations) in at most {TARGET_MS:g} ms")
    for row in r["localize"]:
        if row["nodes"] == 1000:
            ms, verdict = row["markov_step_ms"], "holds" if row["markov_step_ms"] <= TARGET_MS else "MISSED"
            lines.append(f"  {verdict}: the whole Markov step at 1000 nodes took {ms} ms")
    return "\n".join(lines)
