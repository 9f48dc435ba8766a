"""What any arena controller's `record()` gives, in an arena recording, by the shape of each value:
the log of a controller whose registry entry names no log of its own (a user's controller).

    controllers/<agent>/series/<key>   a number (or a 0-d array): a scalar series, one value per tick
    controllers/<agent>/bars/<key>     a 1-D array: a bar chart every `every` ticks
    controllers/<agent>/images/<key>   a 2-D array (not N x 2): a grey image every `every` ticks
    world/records/<agent>/<key>        an N x 2 array: a path in metres over the arena, every `every` ticks

`path` is left to the recorder (world/plans).  Anything else (text, 3-D arrays, None) is left out,
so a controller may keep what only its tests read in the same dict.
"""

from __future__ import annotations

import numpy as np

from swarm.core.series import SeriesLog


def flip(xy: np.ndarray) -> np.ndarray:
    out = np.array(xy, np.float32).reshape(-1, 2)
    out[:, 1] *= -1
    return out


def shape_of(value) -> tuple[str | None, np.ndarray | None]:
    """How a record's value is shown ("series", "bars", "images", "path", or None: not recorded), and
    the value as an array."""
    if not isinstance(value, bool | int | float | np.number | np.bool_ | np.ndarray | list | tuple):
        return None, None
    try:
        a = np.asarray(value, np.float64)
    except (TypeError, ValueError):
        return None, None
    if a.ndim == 0:
        return "series", a
    if a.ndim == 1 and a.size:
        return "bars", a
    if a.ndim == 2 and a.shape[1] == 2:
        return "path", a
    return ("images", a) if a.ndim == 2 and a.size else (None, None)


class RecordLog(SeriesLog):
    """Logs a record() by the shape of its values (the module docstring)."""

    def __init__(self, rr, rec, colours=None, every: int = 10):
        super().__init__(rr, rec, every)
        self.colours = colours

    def capture(self, tick: int, agent: int, record: dict, xy=None) -> None:
        rows = self.tick(agent, tick)
        n = len(self._ticks[agent])  # every series holds one value per tick: NaN where a key was missing
        sparse = tick % self.every == 0
        for key, value in record.items():
            if key == "path":
                continue
            shown, a = shape_of(value)
            if shown == "series":
                rows.setdefault(str(key), [np.nan] * (n - 1)).append(float(a))
            elif shown is not None and sparse:
                self._log_array(tick, agent, str(key), shown, a)
        for column in rows.values():
            if len(column) < n:
                column.append(np.nan)

    def _log_array(self, tick: int, agent: int, key: str, shown: str, a: np.ndarray) -> None:
        rr = self.rr
        self.rec.set_time("tick", sequence=tick)
        if shown == "bars":
            self.rec.log(f"controllers/{agent}/bars/{key}", rr.BarChart(a.astype(np.float32)))
        elif shown == "images":
            self.rec.log(f"controllers/{agent}/images/{key}", rr.Image(a.astype(np.float32)))
        else:
            colour = None if self.colours is None else [self.colours[agent]]
            self.rec.log(f"world/records/{agent}/{key}", rr.LineStrips2D([flip(a)], colors=colour, radii=0.002,
                                                                         draw_order=2.5))  # fmt: skip

    def columns(self, agent: int, name: str, rows: list) -> list[tuple[str, np.ndarray]]:
        return [(f"controllers/{agent}/series/{name}", np.array(rows, np.float64))]

    @staticmethod
    def views(rrb, agent: int, name: str) -> list:
        """The viewer's panels for one robot of a controller: its series, its bar charts, its images."""
        root = f"/controllers/{agent}"
        return [
            rrb.TimeSeriesView(origin=f"{root}/series", name=f"{name} {agent}"),
            rrb.BarChartView(origin=f"{root}/bars", name=f"{name} {agent} bars"),
            rrb.Spatial2DView(origin=f"{root}/images", name=f"{name} {agent} images"),
        ]
