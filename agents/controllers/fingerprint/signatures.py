"""Fingerprints as the topological map's place signature: the likelihood of a
fingerprint at each node (circular alignment against every node's mean in
one compiled call) and the mean of a node's fingerprints.

The mean of strings: the set median (medoid), the member whose alignment
costs to all the others sum least.  It is always a fingerprint the robot
really saw, a spurious or missed feature of one member never enters it, and
it needs no rule for averaging bearings; the paper builds its mean
"between the previous mean fingerprint and the new one" without saying how
(docs/fingerprint.md).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from agents.controllers.fingerprint.align import MAX_LENGTH, SYMBOLS, Matcher, paper_length
from agents.controllers.fingerprint.features import Fingerprint
from agents.controllers.navigation.params import MapParams
from agents.controllers.navigation.topomap import TopoMap, topomap_from_data, topomap_to_data


def pack(strings: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(codes, offsets, lengths in the paper's characters) of a list of symbol strings."""
    codes = np.concatenate(strings).astype(np.int8) if strings else np.zeros(0, np.int8)
    offsets = np.zeros(len(strings) + 1, np.int64)
    offsets[1:] = np.cumsum([len(s) for s in strings])
    return codes, offsets, np.array([paper_length(s) for s in strings], np.int64)


class FingerprintSignatures:
    def __init__(self, matcher: Matcher):
        self.matcher = matcher
        self._means: list[Fingerprint] = []
        self._packed = pack([])
        self._costs: dict[tuple[int, int], float] = {}  # alignment costs between members, kept across joins
        self._held: dict[int, Fingerprint] = {}  # the fingerprints those ids name (held, so no id is reused)

    def likelihoods(self, observation: Fingerprint, means: list[Fingerprint]) -> np.ndarray:
        same = len(means) == len(self._means) and all(a is b for a, b in zip(means, self._means, strict=True))
        if not same:  # a node was added or its mean changed: pack them again (held, so no id is reused)
            self._means, self._packed = list(means), pack([m.codes for m in means])
        return self.matcher.against(observation.codes, *self._packed)

    def mean(self, members: list[Fingerprint]) -> Fingerprint:
        if len(members) <= 2:
            return members[0]
        k = len(members)
        cost = np.zeros((k, k))
        for i in range(k):
            for j in range(i + 1, k):
                cost[i, j] = cost[j, i] = self._cost(members[i], members[j])
        return members[int(np.argmin(cost.sum(axis=1)))]

    def _cost(self, a: Fingerprint, b: Fingerprint) -> float:
        """A node's members are compared again at every join: each pair is aligned once."""
        key = (id(a), id(b))
        if key not in self._costs:
            self._held[id(a)], self._held[id(b)] = a, b
            self._costs[key] = self.matcher.cost(a.codes, b.codes)
        return self._costs[key]


def fingerprint_data(f: Fingerprint) -> list:
    return [f.codes.tolist(), f.bearings.tolist()]


def fingerprint_from_data(data: list) -> Fingerprint:
    """A fingerprint from plain data, checked (symbols, lengths, finite bearings): ValueError if not one."""
    codes = np.array(data[0], np.int64)
    bearings = np.array(data[1], np.float64)
    if not (codes.ndim == bearings.ndim == 1 and len(codes) == len(bearings) and 0 < len(codes) <= MAX_LENGTH
            and ((codes >= 0) & (codes < SYMBOLS)).all() and np.isfinite(bearings).all()):  # fmt: skip
        raise ValueError(f"not a fingerprint: expected [symbols 0-{SYMBOLS - 1}, bearings] as long, "
                         f"1 to {MAX_LENGTH} of them")  # fmt: skip
    return Fingerprint(codes.astype(np.int8), bearings)


def map_to_data(m: TopoMap) -> dict[str, Any]:
    """A fingerprint map as plain data (msgpack- and JSON-safe)."""
    return topomap_to_data(m, fingerprint_data)


def map_from_data(data: dict[str, Any], signatures: FingerprintSignatures, params: MapParams) -> TopoMap:
    m = topomap_from_data(data, signatures, params, fingerprint_from_data, "a fingerprint map",
                          "FingerprintController.map_data()")  # fmt: skip
    for node in m.nodes:  # the mean is one of the members: keep it the same object, as the live map does
        same = [f for f in node.members if np.array_equal(f.codes, node.mean.codes)]
        if same:
            node.mean = same[0]
    return m
