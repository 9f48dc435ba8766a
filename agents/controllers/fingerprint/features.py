"""A fingerprint of a place from the robot's own sensors (Tapus et al. 2006, section 3).

- colour patches `A`..`P`: runs of panorama sectors whose colour is saturated
  enough to have a hue, one feature per run, its letter the hue's bin of 16;
- vertical edges `v`: the panorama's colour boundaries (a patch, a cabinet,
  a door against the wall) and its depth steps (the camera's range jumps at
  door frames and the sides of furniture: in a real image these are the
  vertical lines that light and shade draw);
- corners `c`: the ends of the line segments that Douglas-Peucker fits to
  each unbroken stretch of the laser scan;
- empty space `n`: one per `quantum` of angle between consecutive features
  (a run of them is one symbol of the alignment: align.py).

The features are ordered by bearing, counter-clockwise from the robot's
heading, into a circular string.  Every threshold is a field of
FeatureParams (params.py), and docs/fingerprint.md gives the reasons for each value.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from agents.controllers.fingerprint.align import HUES, MAX_RUN, C, N, V, paper_length, to_string
from agents.controllers.fingerprint.params import FeatureParams

TWO_PI = 2 * math.pi


@dataclass(frozen=True)
class Fingerprint:
    codes: np.ndarray  # int8 symbols (align.py), a run of empty quanta as one
    bearings: np.ndarray  # bearing of each symbol (a run of `n` at the middle of its gap)

    def __str__(self) -> str:
        return to_string(self.codes)

    @property
    def length(self) -> int:
        """In the paper's characters."""
        return paper_length(self.codes)


def hue_saturation(rgb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """HSV hue in [0, 1) and saturation of each colour (n, 3), vectorised."""
    c = np.asarray(rgb, np.float64) / 255.0
    hi, lo = c.max(axis=1), c.min(axis=1)
    span = hi - lo
    sat = np.where(hi > 0, span / np.where(hi > 0, hi, 1.0), 0.0)
    r, g, b = c[:, 0], c[:, 1], c[:, 2]
    safe = np.where(span > 0, span, 1.0)
    hue = np.where(hi == r, ((g - b) / safe) % 6.0, np.where(hi == g, (b - r) / safe + 2.0, (r - g) / safe + 4.0))
    return np.where(span > 0, hue / 6.0, 0.0) % 1.0, sat


def _runs(labels: np.ndarray) -> list[tuple[int, int, int]]:
    """Circular runs (first index, length, label) of equal labels >= 0."""
    n = len(labels)
    if n == 0:
        return []
    change = np.flatnonzero(labels != np.roll(labels, 1))
    if len(change) == 0:
        return [(0, n, int(labels[0]))] if labels[0] >= 0 else []
    out = []
    for k, first in enumerate(change):
        end = change[k + 1] if k + 1 < len(change) else change[0] + n
        if labels[first] >= 0:
            out.append((int(first), int(end - first), int(labels[first])))
    return out


def _merge(bearings: np.ndarray, gap: float) -> np.ndarray:
    """One bearing per circular cluster of bearings closer than `gap` (its first)."""
    if len(bearings) < 2:
        return bearings
    b = np.sort(bearings % TWO_PI)
    keep = np.diff(b, prepend=b[-1] - TWO_PI) >= gap
    if not keep.any():
        return b[:1]
    return b[keep]


def camera_features(rgb: np.ndarray, ranges: np.ndarray, p: FeatureParams) -> tuple[np.ndarray, np.ndarray]:
    """(codes, bearings) of the colour patches and vertical edges of a panorama
    whose sector k looks at bearing 2 pi k / sectors."""
    sectors = len(rgb)
    width = TWO_PI / sectors
    hue, sat = hue_saturation(rgb)
    bins = np.where(sat >= p.saturation, np.minimum((hue * HUES).astype(np.int64), HUES - 1), -1)
    codes, bearings = [], []
    for first, length, label in _runs(bins):
        if length >= p.min_patch:
            codes.append(label)
            bearings.append(((first + (length - 1) / 2) * width) % TWO_PI)
    c = np.asarray(rgb, np.float64)
    colour = np.abs(c - np.roll(c, 1, axis=0)).max(axis=1) >= p.colour_step
    r = np.asarray(ranges, np.float64)
    prev = np.roll(r, 1)
    depth = (np.abs(r - prev) >= p.depth_step) & (np.abs(r - prev) >= p.depth_ratio * np.minimum(r, prev))
    edges = _merge((np.flatnonzero(colour | depth) - 0.5) * width, p.merge)  # between sector k-1 and k
    codes += [V] * len(edges)
    bearings += list(edges)
    return np.array(codes, np.int8), np.array(bearings, np.float64)


def _douglas_peucker(points: np.ndarray, epsilon: float) -> list[int]:
    """Indices of the kept vertices of the polyline `points` (iterative)."""
    keep = {0, len(points) - 1}
    stack = [(0, len(points) - 1)]
    while stack:
        i, j = stack.pop()
        if j <= i + 1:
            continue
        a, b = points[i], points[j]
        ab = b - a
        norm = math.hypot(ab[0], ab[1])
        seg = points[i + 1 : j] - a
        dist = np.abs(ab[0] * seg[:, 1] - ab[1] * seg[:, 0]) / norm if norm > 0 else np.hypot(seg[:, 0], seg[:, 1])
        k = int(np.argmax(dist))
        if dist[k] > epsilon:
            keep.add(i + 1 + k)
            stack += [(i, i + 1 + k), (i + 1 + k, j)]
    return sorted(keep)


def laser_corners(scan: np.ndarray, max_range: float, p: FeatureParams) -> np.ndarray:
    """Bearings of the ends of the segments that Douglas-Peucker fits to the
    unbroken stretches of a 360-degree scan (beam k at bearing 2 pi k / beams)."""
    beams = len(scan)
    r = np.asarray(scan, np.float64)
    angle = np.arange(beams) * TWO_PI / beams
    valid = r < max_range * 0.999
    jump = np.abs(r - np.roll(r, 1)) > p.break_range
    breaks = ~valid | jump | ~np.roll(valid, 1)
    if not valid.any():
        return np.zeros(0)
    if breaks.any():  # walk the circle from a break, so that no stretch wraps
        first = int(np.flatnonzero(breaks)[0])
    else:  # a closed loop: cut it at a vertex Douglas-Peucker keeps, so that the cut makes no corner
        pts = np.column_stack((r * np.cos(angle), r * np.sin(angle)))
        kept = _douglas_peucker(np.vstack((pts, pts[:1])), p.epsilon)
        first = kept[1] % beams if len(kept) > 2 else 0
    order = (np.arange(beams) + first) % beams
    corners = []
    stretch: list[int] = []
    closed = not breaks.any()
    for k in [*order, *([first] if closed else []), -1]:
        if k == -1 or (breaks[k] and not closed):
            if len(stretch) >= 2:
                idx = np.array(stretch)
                pts = np.column_stack((r[idx] * np.cos(angle[idx]), r[idx] * np.sin(angle[idx])))
                kept = _douglas_peucker(pts, p.epsilon)
                for u, w in itertools.pairwise(kept):
                    if math.dist(pts[u], pts[w]) >= p.min_segment:
                        corners += [angle[idx[u]], angle[idx[w]]]
            stretch = []
        if k != -1 and valid[k]:
            stretch.append(int(k))
    return _merge(np.array(corners), p.merge)


def fingerprint(rgb: np.ndarray, camera_range: np.ndarray, scan: np.ndarray, max_range: float,
                p: FeatureParams) -> Fingerprint:  # fmt: skip
    """The circular string of a place: features by bearing, empty space between."""
    codes, bearings = camera_features(rgb, camera_range, p)
    corners = laser_corners(scan, max_range, p)
    codes = np.concatenate((codes, np.full(len(corners), C, np.int8)))
    bearings = np.concatenate((bearings, corners)) % TWO_PI
    order = np.lexsort((codes, bearings))  # by bearing; at one bearing: hues, then v, then c
    codes, bearings = codes[order], bearings[order]
    if len(codes) == 0:
        return Fingerprint(np.array([N + min(int(TWO_PI // p.quantum), MAX_RUN) - 1], np.int8), np.zeros(1))
    gaps = (np.roll(bearings, -1) - bearings) % TWO_PI
    if len(codes) == 1:
        gaps[:] = TWO_PI
    out_codes, out_bearings = [], []
    for code, bearing, gap in zip(codes, bearings, gaps, strict=True):
        out_codes.append(code)
        out_bearings.append(bearing)
        k = min(int(gap // p.quantum), MAX_RUN)
        if k:  # one symbol for the run of k quanta, at the middle of the gap
            out_codes.append(N + k - 1)
            out_bearings.append((bearing + gap / 2) % TWO_PI)
    return Fingerprint(np.array(out_codes, np.int8), np.array(out_bearings, np.float64))
