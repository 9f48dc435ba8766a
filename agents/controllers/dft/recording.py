"""Neural fields in an arena recording: what explains a dft robot's choices
(in process: the recorder asks each controller that keeps fields for its
`record()`).

    fields/<agent>/M/<EB>            motivation field of each EB (N, S, W, E), an image every `every` (20) ticks
    fields/<agent>/I/<EB>            intention fields, likewise
    fields/<agent>/intention/<EB>    max f(u_I) per tick (the paper's Figure 10, bottom)
    fields/<agent>/action/<EB>       max f(u_A) per tick: how strongly each action field drives the wheels
    fields/<agent>/turn/<EB>         where that action field peaks, as a turning angle (rad; + is left)

Images are north up, activation -10..10 in steps of 0.5 mapped to grey
0..240, PNG-encoded: the steps hide the field noise (std 0.2 per step), so the
resting floor at h is one grey and a 100 x 100 field packs into about 1 KB.
"""

from __future__ import annotations

import io

import numpy as np

from swarm.core.series import SeriesLog

EBS = ("N", "S", "W", "E")
FIELD_RANGE = 10.0
STEP = 0.5  # activation per grey level


def png(u: np.ndarray) -> bytes:
    """A field's activation as an 8-bit grey PNG, north up."""
    from PIL import Image

    level = np.rint((np.clip(np.asarray(u, np.float64), -FIELD_RANGE, FIELD_RANGE) + FIELD_RANGE) / STEP)
    grey = (level * (240 / (2 * FIELD_RANGE / STEP))).astype(np.uint8)
    buf = io.BytesIO()
    Image.fromarray(grey[::-1]).save(buf, format="PNG", optimize=True)
    return buf.getvalue()


class FieldLog(SeriesLog):
    def __init__(self, rr, rec, colours=None, every: int = 20):
        super().__init__(rr, rec, every)

    def capture(self, tick: int, agent: int, record: dict[str, np.ndarray], xy=None) -> None:
        series = self.tick(agent, tick)
        series.setdefault("intention", []).append(np.asarray(record["intention_max"], np.float64))
        action = np.asarray(record["action"])
        series.setdefault("action", []).append(action.max(axis=1).astype(np.float64))
        angles = -np.pi + np.argmax(action, axis=1) * 2 * np.pi / action.shape[1]
        series.setdefault("turn", []).append(-angles)  # cells above the middle lie on the robot's right: turn < 0
        if tick % self.every == 0:
            self.rec.set_time("tick", sequence=tick)
            for kind, key in (("M", "motivation"), ("I", "intention")):
                for d, u in zip(EBS, record[key], strict=True):
                    self.rec.log(f"fields/{agent}/{kind}/{d}",
                                 self.rr.EncodedImage(contents=png(u), media_type="image/png"))  # fmt: skip

    def columns(self, agent: int, name: str, rows: list) -> list[tuple[str, np.ndarray]]:
        values = np.stack(rows)
        return [(f"fields/{agent}/{name}/{d}", values[:, k]) for k, d in enumerate(EBS)]

    @staticmethod
    def views(rrb, agent: int, name: str) -> list:
        """The viewer's panels for one robot: its motivation and intention fields, and the intentions
        and actions over time (the paper's Figure 10)."""
        root = f"/fields/{agent}"
        return [rrb.Spatial2DView(origin=f"{root}/M", name=f"{name} {agent} motivation"),
                rrb.Spatial2DView(origin=f"{root}/I", name=f"{name} {agent} intention"),
                rrb.TimeSeriesView(origin=f"{root}/intention", name=f"{name} {agent} max intention"),
                rrb.TimeSeriesView(origin=f"{root}/action", name=f"{name} {agent} action")]  # fmt: skip
