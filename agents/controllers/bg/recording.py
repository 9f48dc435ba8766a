"""The BG animat in an arena recording: what explains its choices (in
process: the recorder asks each controller that keeps channels for its
`record()`).  Its map goes through agents/controllers/navigation/recording.py like the
fingerprint robot's, with the resources its nodes hold in their labels.

    bg/<agent>/energy, potential, disorientation        E, Ep, D per tick
    bg/<agent>/motivation/<E|Ep|BKA|DA>                 eq. 2 per tick
    bg/<agent>/act                                      0 none, 1 ReloadE, 2 ReloadEp, per tick
    bg/<agent>/direction                                the ventral loop's direction (deg; nan: none)
    bg/<agent>/reflex                                   1 while the sonar reflex has the body
    bg/<agent>/dorsal, bg/<agent>/ventral               disinhibition per channel, a bar chart every `every` ticks
"""

from __future__ import annotations

import numpy as np

from swarm.core.series import SeriesLog

SCALARS = ("energy", "potential", "disorientation", "act", "direction", "reflex")
MOTIVATIONS = ("E", "Ep", "BKA", "DA")


class ChannelLog(SeriesLog):
    def __init__(self, rr, rec, colours=None, every: int = 4):
        super().__init__(rr, rec, every)

    def capture(self, tick: int, agent: int, record: dict[str, np.ndarray], xy=None) -> None:
        if "energy" not in record:
            return
        rows = self.tick(agent, tick)
        for k in SCALARS:
            value = float(record[k])
            rows.setdefault(k, []).append(np.degrees(value) if k == "direction" else value)
        for k, m in zip(MOTIVATIONS, np.asarray(record["motivations"], np.float64), strict=True):
            rows.setdefault(f"motivation/{k}", []).append(float(m))
        if tick % self.every == 0:
            self.rec.set_time("tick", sequence=tick)
            for loop in ("dorsal", "ventral"):
                self.rec.log(f"bg/{agent}/{loop}", self.rr.BarChart(np.asarray(record[loop], np.float32)))

    def columns(self, agent: int, name: str, rows: list) -> list[tuple[str, np.ndarray]]:
        return [(f"bg/{agent}/{name}", np.array(rows))]

    @staticmethod
    def views(rrb, agent: int, name: str) -> list:
        """The viewer's panels for one animat: its variables and motivations, and both loops' channels."""
        return [rrb.TimeSeriesView(origin=f"/bg/{agent}", name=f"{name} {agent}"),
                rrb.BarChartView(origin=f"/bg/{agent}/dorsal", name=f"{name} {agent} dorsal"),
                rrb.BarChartView(origin=f"/bg/{agent}/ventral", name=f"{name} {agent} ventral")]  # fmt: skip
