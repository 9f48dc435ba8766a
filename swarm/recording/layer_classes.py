"""Grid layers as class images for recordings: one compiled rule for both runtimes.

A recording holds each grid layer as a 16-bit class image that the viewer
colours from a static annotation context (swarm.recording.grid), so nothing is
coloured per tick.  The in-process engine writes class images straight from
its compiled loop (swarm.engines.grid.record_tick); the world process converts a
layer per tick with the same kernel.

Classes: 0 is "nothing here" (transparent).  Marks and resources map their
value in 0..scale to 1 + level, one level per value up to `levels` levels,
value ranges beyond (values above the scale count as the scale).  Trails map
their id to 1 + id mod 20.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from world_server.grid.face.layout import MARK_NONE

K_MARKS, K_TRAILS, K_RESOURCES = 0, 1, 2
TRAIL_COLOURS = 20
MAX_LEVELS = (1024, TRAIL_COLOURS, 64)  # per kind: marks keep their value up to 1023, resources drive opacity


def n_levels(kind: int, scale: int) -> int:
    return TRAIL_COLOURS if kind == K_TRAILS else min(scale + 1, MAX_LEVELS[kind])


@njit(cache=True, inline="always")
def _class_of(kind, value, scale, levels):
    if kind == K_TRAILS:
        return value % levels + 1 if value > 0 else 0
    if (kind == K_MARKS and value == MARK_NONE) or (kind == K_RESOURCES and value <= 0):
        return 0
    return 1 + min(max(value, 0), scale) * (levels - 1) // max(scale, 1)


@njit(cache=True)
def class_image(kind, layer, scale, levels, out):
    """out[r, c] = the class of layer[r, c] (out: uint16, same shape)."""
    for r in range(layer.shape[0]):
        for c in range(layer.shape[1]):
            out[r, c] = _class_of(kind, layer[r, c], scale, levels)


def class_images(kind: int, layers: np.ndarray, scale: int) -> np.ndarray:
    """Class images (k, H, W) uint16 of a stack of layer snapshots."""
    out = np.empty(layers.shape, np.uint16)
    levels = n_levels(kind, scale)
    for i in range(len(layers)):
        class_image(kind, layers[i], scale, levels, out[i])
    return out


def level_range(kind: int, level: int, scale: int) -> tuple[int, int]:
    """The values in 0..scale that map to class 1 + level (for the legend)."""
    n = n_levels(kind, scale)
    if n == scale + 1:
        return level, level
    low = -(-level * scale // (n - 1))
    high = min(scale, -(-(level + 1) * scale // (n - 1)) - 1)
    return low, max(low, high)
