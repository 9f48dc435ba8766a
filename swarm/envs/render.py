"""A top-down picture of an arena world in numpy: the floor, its walls in their colours and the
robots as discs with a heading tick.  The walls are drawn once per world (again only when an
obstacle comes or goes), each robot within its own box, so a frame costs about a copy."""

from __future__ import annotations

import numpy as np

from world_server.arena.world import ArenaWorld

PIXELS = 400  # along the arena's longer side
FLOOR = (235, 235, 235)
TICK = (255, 255, 255)


class TopDown:
    """Frames of one world, north up, `pixels` along its longer side."""

    def __init__(self, world: ArenaWorld, pixels: int = PIXELS):
        self.world = world
        sx, sy = world.scenario.size
        self.scale = pixels / max(sx, sy)
        self.h, self.w = max(1, round(sy * self.scale)), max(1, round(sx * self.scale))
        self.layers: bytes | None = None  # the walls' layer bits the background was drawn with
        self.background = np.empty((self.h, self.w, 3), np.uint8)

    def frame(self) -> np.ndarray:
        """(h, w, 3) uint8 of the world now."""
        w = self.world
        if self.layers != w.seg_on.tobytes():
            self.layers = w.seg_on.tobytes()
            self.background[...] = FLOOR
            for seg, rgb in zip(w.segs[w.seg_on != 0], w.seg_rgb[w.seg_on != 0], strict=True):
                self.segment(self.background, seg, 1.0 / self.scale, rgb)
        img = self.background.copy()
        for a in np.flatnonzero(w.in_world):
            x, y, theta = w.pose[a]
            r = float(w.radius[a])
            xs, ys, box = self.box(x - r, y - r, x + r, y + r)
            img[box][(xs - x) ** 2 + (ys - y) ** 2 <= r * r] = w.robot_rgb[a]
            self.segment(img, (x, y, x + r * np.cos(theta), y + r * np.sin(theta)), max(1.0 / self.scale, r / 6), TICK)
        return img

    def box(self, x0: float, y0: float, x1: float, y1: float) -> tuple[np.ndarray, np.ndarray, tuple[slice, slice]]:
        """The pixel centres (world x, y) of the pixels covering this rectangle, and their slice of the image."""
        s = self.scale
        c0, c1 = max(0, int(x0 * s)), min(self.w, int(np.ceil(x1 * s)) + 1)
        r0, r1 = max(0, int((self.h / s - y1) * s)), min(self.h, int(np.ceil((self.h / s - y0) * s)) + 1)
        xs = ((np.arange(c0, c1) + 0.5) / s)[None, :]
        ys = (self.h - (np.arange(r0, r1) + 0.5)) / s
        return xs, ys[:, None], (slice(r0, r1), slice(c0, c1))

    def segment(self, img: np.ndarray, seg, width: float, rgb) -> None:
        """Paint the pixels within `width` of the segment."""
        x0, y0, x1, y1 = (float(v) for v in seg)
        xs, ys, box = self.box(min(x0, x1) - width, min(y0, y1) - width, max(x0, x1) + width, max(y0, y1) + width)
        dx, dy = x1 - x0, y1 - y0
        length2 = dx * dx + dy * dy
        t = 0.0 if length2 == 0 else np.clip(((xs - x0) * dx + (ys - y0) * dy) / length2, 0.0, 1.0)
        img[box][(xs - x0 - t * dx) ** 2 + (ys - y0 - t * dy) ** 2 <= width * width] = rgb


class Canvas:
    """The frames of whichever world an env holds now: a new TopDown when reset made a new world."""

    def __init__(self) -> None:
        self.top: TopDown | None = None

    def frame(self, world: ArenaWorld) -> np.ndarray:
        if self.top is None or self.top.world is not world:
            self.top = TopDown(world)
        return self.top.frame()
