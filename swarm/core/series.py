"""Per-agent scalar series a controller's log gathers tick by tick and sends
as columns at each flush (one rerun call per entity, not one per tick).

A controller's log (ControllerSpec.records) is built once per recording as
Log(rr, rec, colours), is given capture(tick, agent, record, xy) with the
controller's record() and its robot's true position at every recorded tick,
and flush() with the recording."""

from __future__ import annotations

import numpy as np


class SeriesLog:
    """Subclasses append to `self.rows(agent)[name]` in `capture` (after `self.tick(agent, tick)`) and say
    where each series goes and what its columns are in `columns(agent, name, rows)`."""

    def __init__(self, rr, rec, every: int):
        self.rr, self.rec, self.every = rr, rec, every
        self._ticks: dict[int, list[int]] = {}
        self._rows: dict[int, dict[str, list]] = {}

    def tick(self, agent: int, tick: int) -> dict[str, list]:
        self._ticks.setdefault(agent, []).append(tick)
        return self._rows.setdefault(agent, {})

    def columns(self, agent: int, name: str, rows: list) -> list[tuple[str, np.ndarray]]:
        raise NotImplementedError

    def flush(self) -> None:
        for agent, ticks in self._ticks.items():
            if not ticks:
                continue
            index = [self.rr.TimeColumn("tick", sequence=np.array(ticks, np.int64))]
            for name, rows in self._rows[agent].items():
                for path, values in self.columns(agent, name, rows):
                    self.rec.send_columns(path, indexes=index, columns=self.rr.Scalars.columns(scalars=values))
            self._ticks[agent] = []
            self._rows[agent] = {}
