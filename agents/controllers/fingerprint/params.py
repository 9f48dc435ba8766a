"""The fingerprint model's one declared parameter set (Tapus, Battaglia & Siegwart 2006): the
controller's, the feature extraction's and the alignment's numbers, each with its provenance.

PAPER: the spacing of fingerprints along the tour (section 3, Figure 4).  The paper names its
features, the alignment with uncertainty and theta without numbers, and its authors' code is not
available: every other value is ours, each with its reason (docs/fingerprint.md: Features,
Matching, the map).  The topological map's own numbers are navigation's (agents/controllers/
navigation/params.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from swarm.core.params import OURS, PAPER, declared
from swarm.core.tables import params_from_table

DRIVES = ("route", "explore")
MODES = ("map", "localize")
FILTERS = ("grid", "links")


@dataclass(frozen=True)
class FingerprintParams:
    spacing: float = declared(
        0.15,
        source=PAPER,
        where="metres between fingerprints: section 3, Figure 4, 500 data sets over a 75 m tour (75 m / 500)",
    )
    drive: str = declared(
        "route",
        source=OURS,
        reason=(
            "route: the carrot along the group's route, as the paper's robot was driven along a tour "
            "(section 3); explore: wander"
        ),
    )
    mode: str = declared(
        "map",
        source=OURS,
        reason=(
            "map: build the map, the paper's first experiment; localize: on the map given in "
            "params['topomap'] (its second)"
        ),
    )
    theta: float = declared(
        0.5,
        source=OURS,
        reason=(
            "largest dissimilarity at which a fingerprint joins the current node: the paper "
            "determines theta experimentally and does not give it (section 3); P(match) > 0.5 "
            "(docs/fingerprint.md)"
        ),
    )
    keep: int = declared(
        30,
        source=OURS,
        reason=(
            "fingerprints a node keeps for its mean: the paper builds its mean without saying how "
            "(docs/fingerprint.md, the map)"
        ),
    )
    closure: float = declared(
        0.5,
        source=OURS,
        reason=(
            "belief in a known node that closes a loop: at least half on it (docs/fingerprint.md, "
            "loop closing through localization)"
        ),
    )
    sharpness: float = declared(
        2.0,
        source=OURS,
        reason=(
            "the Markov filter weighs nodes by P(match) ** sharpness: a look-alike room still gets "
            "0.5-0.8 against the right one's 0.9 (docs/fingerprint.md)"
        ),
    )
    filter: str = declared(
        "grid",
        source=OURS,
        reason=(
            "localizing, the belief that decides: on the map's odometric grid (99.4-99.7% against "
            "96-97% over the links alone, docs/fingerprint.md)"
        ),
    )

    @classmethod
    def from_table(cls, table: dict[str, Any] | None) -> FingerprintParams:
        p = params_from_table(cls, table, "fingerprint", ints=("keep",), texts=("drive", "mode", "filter"),
                              nested=("features", "align"))  # fmt: skip
        if p.drive not in DRIVES:
            raise ValueError(f"[fingerprint].drive: {p.drive!r}; expected one of {', '.join(DRIVES)}")
        if p.mode not in MODES:
            raise ValueError(f"[fingerprint].mode: {p.mode!r}; expected one of {', '.join(MODES)}")
        if p.filter not in FILTERS:
            raise ValueError(f"[fingerprint].filter: {p.filter!r}; expected one of {', '.join(FILTERS)}")
        if not (p.spacing > 0 and 0 < p.theta < 1 and p.keep >= 1 and 0 < p.sharpness <= 10):
            raise ValueError("[fingerprint]: spacing > 0, 0 < theta < 1, keep >= 1 and 0 < sharpness <= 10 "
                             "are required")  # fmt: skip
        return p


@dataclass(frozen=True)
class FeatureParams:
    """The feature extraction's numbers: the paper names the features (section 3) without any threshold; all
    ours (docs/fingerprint.md, Features).
    """

    saturation: float = declared(
        0.35,
        source=OURS,
        reason="a sector has a hue when its HSV saturation is at least this (docs/fingerprint.md, Features)",
    )
    min_patch: int = declared(
        2,
        source=OURS,
        reason="sectors (degrees, on the scout) a colour patch must span (docs/fingerprint.md, Features)",
    )
    colour_step: float = declared(
        30.0,
        source=OURS,
        reason="an edge where adjacent sectors differ this much in some RGB channel (docs/fingerprint.md, Features)",
    )
    depth_step: float = declared(
        0.25,
        source=OURS,
        reason=(
            "or where the camera's range jumps this much (metres): door frames, furniture sides, what"
            " light and shade draw in a real image"
        ),
    )
    depth_ratio: float = declared(
        0.15, source=OURS, reason="... and this share of the nearer range (docs/fingerprint.md, Features)"
    )
    merge: float = declared(
        math.radians(3.0),
        source=OURS,
        reason="edges (or corners) closer than this are one (docs/fingerprint.md, Features)",
    )
    break_range: float = declared(
        0.3,
        source=OURS,
        reason="the laser scan breaks into stretches at range jumps above this (metres) before Douglas-Peucker",
    )
    epsilon: float = declared(
        0.06,
        source=OURS,
        reason="Douglas-Peucker tolerance (metres): the paper names the algorithm (section 3) without its tolerance",
    )
    min_segment: float = declared(
        0.4, source=OURS, reason="segments shorter than this give no corners (metres; docs/fingerprint.md, Features)"
    )
    quantum: float = declared(
        math.radians(20.0),
        source=OURS,
        reason=(
            "one `n` per this much empty angle: the paper's 'n' gives the angular distance between "
            "features without a unit (section 3)"
        ),
    )

    @classmethod
    def from_table(cls, table: dict | None) -> FeatureParams:
        return params_from_table(cls, table, "fingerprint.features", ints=("min_patch",))


@dataclass(frozen=True)
class AlignParams:
    """Global alignment with uncertainty: the paper names the method ([26], after Needleman-Wunsch) without its
    constants; ours are negative log-probabilities of what makes two views of one place differ, chosen by
    the area under the ROC curve of same- against different-place pairs (docs/fingerprint.md, Matching).
    """

    miss_hue: float = declared(
        0.02, source=OURS, reason="chance that a colour patch is missed or spurious (docs/fingerprint.md, Matching)"
    )
    miss_edge: float = declared(
        0.5, source=OURS, reason="chance that a vertical edge is missed or spurious (docs/fingerprint.md, Matching)"
    )
    miss_corner: float = declared(
        0.5, source=OURS, reason="chance that a laser corner is missed or spurious (docs/fingerprint.md, Matching)"
    )
    miss_space: float = declared(
        0.5, source=OURS, reason="chance of one empty-space quantum more or less (docs/fingerprint.md, Matching)"
    )
    hue_near: float = declared(
        1.2, source=OURS, reason="cost of a hue patch read one bin off (docs/fingerprint.md, Matching)"
    )
    wrong: float = declared(
        4.0,
        source=OURS,
        reason=(
            "any other substitution: more than a gap of either feature, so one missing feature costs "
            "less than one wrong one"
        ),
    )
    centre: float = declared(
        0.544,
        source=OURS,
        reason=(
            "P(match) = 1 / (1 + exp((d - centre) / width)), d the cost per character of the longer "
            "string: fitted by logistic regression on office (swarm experiment fingerprint-calibrate,"
            " docs/fingerprint.md)"
        ),
    )
    width: float = declared(
        0.122,
        source=OURS,
        reason="the logistic's width, fitted with centre on office (docs/fingerprint.md, Probability)",
    )

    @classmethod
    def from_table(cls, table: dict | None) -> AlignParams:
        return params_from_table(cls, table, "fingerprint.align")

    def probability(self, cost: np.ndarray | float, longer: np.ndarray | int) -> np.ndarray:
        """P(match) from a cost (in nats) and the longer string's length in the paper's characters."""
        d = np.asarray(cost, np.float64) / np.maximum(np.asarray(longer, np.float64), 1.0)
        return 1.0 / (1.0 + np.exp(np.clip((d - self.centre) / self.width, -50.0, 50.0)))
