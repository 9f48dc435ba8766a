"""The navigation modules' one declared parameter set: the topological map (topomap.py) and the
Markov localization on its odometric grid (gridbelief.py), shared by the fingerprint controller
(Tapus et al. 2006) and the BG animat's Filliat-style map (Girard et al. 2005).  Neither paper gives
these numbers and no original code does: every value is ours, each with its reason
(docs/fingerprint.md; docs/bg.md, Navigation).
"""

from __future__ import annotations

from dataclasses import dataclass

from swarm.core.params import OURS, declared


@dataclass(frozen=True)
class MapParams:
    """The topological map's numbers (the fingerprint paper's map, its [27] for loops; the BG animat's Filliat-
    style map): none is given by either paper, all ours (docs/fingerprint.md, the map; docs/bg.md,
    Navigation).  The BG animat sets theta, closure_match, merge_match, near, recent and closure_radius from
    its own NavParams; the values below are the fingerprint robot's and, for the rest, both.
    """

    theta: float = declared(
        0.5,
        source=OURS,
        reason=(
            "the largest dissimilarity at which an observation joins a node: the fingerprint paper's "
            "theta, determined experimentally and not given (section 3)"
        ),
    )
    keep: int = declared(
        30,
        source=OURS,
        reason="observations a node keeps to compute its mean from: the paper builds its mean without saying how",
    )
    closure: float = declared(
        0.5,
        source=OURS,
        reason=(
            "a loop closes when the belief, the current node left out, gives a known node this: at "
            "least half (docs/fingerprint.md)"
        ),
    )
    closure_match: float = declared(
        0.9,
        source=OURS,
        reason=(
            "... and the observation matches it this well: a wrong loop bends the map's topology, a "
            "missed one only adds a node (docs/fingerprint.md)"
        ),
    )
    young: int = declared(
        5,
        source=OURS,
        reason=(
            "a node this young (observations, first visit) folds into a known one it turns out to be:"
            " late closing (docs/fingerprint.md)"
        ),
    )
    merge_match: float = declared(
        0.9,
        source=OURS,
        reason=(
            "another robot's node is one of ours when it matches this well (no odometry to help); "
            "with 0.8 look-alike rooms merged (docs/fingerprint.md)"
        ),
    )
    near: float = declared(
        1.5,
        source=OURS,
        reason=(
            "a new node is linked to every node observed this close (odometry): the corridor before a"
            " door and after it meet (docs/fingerprint.md)"
        ),
    )
    recent: float = declared(
        20.0,
        source=OURS,
        reason="... within this much travel: odometry drifts, farther back near means little (docs/fingerprint.md)",
    )
    kappa: float = declared(
        2.0,
        source=OURS,
        reason="concentration of the link direction model (von Mises): weight exp(2 (cos - 1)) (docs/fingerprint.md)",
    )
    spread: float = declared(
        1e-2,
        source=OURS,
        reason="belief spread to every node at each prediction (kidnapping, errors): 1% (docs/fingerprint.md)",
    )
    floor: float = declared(
        1e-3, source=OURS, reason="likelihood floor: one bad match never rules a node out (docs/fingerprint.md)"
    )
    sharpness: float = declared(
        1.0,
        source=OURS,
        reason=(
            "the correction weighs each node by likelihood ** sharpness; 1 for the BG animat, the "
            "fingerprint controller sets its own"
        ),
    )
    closure_radius: float | None = declared(
        None,
        source=OURS,
        reason=(
            "a loop closes only onto a node this near by odometry; None, anywhere (the fingerprint "
            "robot; the BG animat sets its own)"
        ),
    )


@dataclass(frozen=True)
class GridParams:
    """Markov localization on the map's odometric grid: ours, the fingerprint paper localizes with a POMDP over
    nodes ([27]) without numbers (docs/fingerprint.md).
    """

    cell: float = declared(0.2, source=OURS, reason="metres per cell: small against a node's stretch of corridor")
    reach: float = declared(
        1.0,
        source=OURS,
        reason=(
            "a cell within this of an observation stands for that observation's node; 0.7-1.5 m made "
            "no difference (docs/fingerprint.md)"
        ),
    )
    slip: float = declared(
        0.2,
        source=OURS,
        reason=(
            "odometry and map-frame error, m per sqrt(m) travelled (the belief's blur); 0.1 or 0.2 "
            "made no difference (docs/fingerprint.md)"
        ),
    )
    spread: float = declared(
        1e-3,
        source=OURS,
        reason="belief spread to every mapped cell at each step (errors, kidnapping) (docs/fingerprint.md)",
    )
    off_map: float = declared(
        0.6,
        source=OURS,
        reason=(
            "weight of a cell farther than reach from every observation: a place off the map matches "
            "a view about as well as a look-alike room (P 0.5-0.8), so the belief follows the robot "
            "into a room the map lacks; chosen on seeds 0-2 among 0.001, 0.3, 0.5, 0.6, 0.7 "
            "(docs/fingerprint.md)"
        ),
    )
    sharpness: float = declared(
        1.0,
        source=OURS,
        reason=(
            "each cell weighed by its node's P(match) ** sharpness (TopoMap.correct): 1, the exponent"
            " tried against 1.5 and 2 (docs/fingerprint.md)"
        ),
    )
