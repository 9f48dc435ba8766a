"""Rerun recordings of runs: written while the run goes, streamed to disk.

Layout of a recording (timeline `tick`; the record at tick t shows the world
after tick t's actions):

    run/meta            static: JSON of scenario, seed, controller, agents, versions
    run/summary         static: JSON of the summary the run printed (for people)
    world/obstacles     static RGBA image (walls, free cells)
    world/base          static point
    world/marks         class image: mark + 1 (0 = unmarked), coloured by a static
                        viridis annotation context (logged only when they change)
    world/trails        class image: trail id mod 20 + 1 (0 = none), 20 colours
    world/resources     class image: remaining quantity, opacity rising with it
    world/agents        one batched point cloud, class id = agent state (STATES)
    metrics/<name>      scalar time series (METRICS, and agents/<state> counts)

Capturing a tick only copies arrays (and only the layers that changed); the
rerun calls run once per `flush_every` ticks with `send_columns`, so recording
costs little per tick and memory stays bounded.  Grid layers travel as 16-bit
class images and the viewer colours them from the annotation contexts: no
colouring per tick here, and half the bytes of RGBA.
"""

from __future__ import annotations

import functools
import json
import platform
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

import numpy as np

from swarm.recording.layer_classes import K_MARKS, K_TRAILS, class_images, level_range, n_levels
from swarm.recording.sinks import stream_to
from world_server.grid.bodies import cell_centres
from world_server.grid.face.layout import A_MODE, ERASE, RETURN, RETURN_COLOUR, RETURN_MEND, RETURN_REMOVE, SEARCH
from world_server.grid.world import C_DELIVERED, C_EXPLORED, C_OPTIMAL, L_MARK, L_RES, L_TRAIL, GridWorld

STATES = ("searching", "returning", "colouring", "removing", "carrying", "absent")
STATE_COLOURS = ((80, 160, 255), (170, 170, 170), (60, 200, 90), (230, 60, 60), (255, 190, 0), (90, 90, 90))
_MODE_TO_STATE = np.zeros(8, dtype=np.uint16)
_MODE_TO_STATE[[SEARCH, RETURN, RETURN_COLOUR, RETURN_MEND, RETURN_REMOVE, ERASE]] = [0, 1, 2, 2, 3, 3]
CARRYING, ABSENT = STATES.index("carrying"), STATES.index("absent")

# Time series, in the order they are captured.
METRICS = ("delivered", "in_transit", "explored_cells", "optimal_cells", "optimal_share", "agents_alive",
           "tick_ms", "rejected_messages")  # fmt: skip
LAYERS = {
    "marks": L_MARK,
    "trails": L_TRAIL,
    "resources": L_RES,
}  # in the order of swarm.recording.layer_classes' kinds
FORMAT_VERSION = 1


def agent_states(modes: np.ndarray, payload: np.ndarray, present: np.ndarray) -> np.ndarray:
    """Class id per agent: the controller's mode, 'carrying' for a plain
    return with a load, 'absent' for an empty slot."""
    states = _MODE_TO_STATE[np.clip(modes, 0, len(_MODE_TO_STATE) - 1)]
    states = np.where((modes == RETURN) & (payload > 0), CARRYING, states)
    return np.where(present, states, ABSENT).astype(np.uint16)


@functools.cache
def software_versions() -> dict[str, str]:
    versions = {"python": platform.python_version()}
    for dist in ("swarm", "numpy", "numba", "eclipse-zenoh", "pymunk", "rerun-sdk", "msgpack"):
        try:
            versions[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            versions[dist] = "not installed"
    return versions


@dataclass
class Block:
    """Consecutive recorded ticks: per tick and agent arrays, and for each grid
    layer the snapshots of the ticks where it changed."""

    ticks: np.ndarray  # (T,)
    xy: np.ndarray  # (T, n, 2) float32 body positions
    modes: np.ndarray  # (T, n) controller modes (A_MODE)
    payload: np.ndarray  # (T, n)
    present: np.ndarray  # (T, n) bool
    counters: np.ndarray  # (T, N_COUNTERS)
    tick_ms: np.ndarray  # (T,)
    rejected: np.ndarray  # (T,)
    layers: dict[str, tuple[np.ndarray, np.ndarray]]  # name -> (ticks (k,), snapshots (k, H, W))


class EngineTap:
    """Recording buffers the compiled engine loop fills (swarm.engines.grid.run_ticks):
    a whole block of ticks is recorded without returning to Python per tick."""

    def __init__(self, recorder: Recorder):
        self.recorder = recorder
        w = recorder.world
        n, (h, w_) = len(w.pos), w.layout.shape
        self.block = int(max(8, min(512, 8_000_000 // (len(LAYERS) * h * w_ * 8))))
        self.pos = np.zeros((self.block, n, 2), np.int64)
        self.modes = np.zeros((self.block, n), np.int64)
        self.payload = np.zeros((self.block, n), np.int64)
        self.counters = np.zeros((self.block, len(w.counters)), np.int64)
        self.last = np.stack([w.layers[i] for i in LAYERS.values()])
        self.last[:] = -1  # nothing recorded yet: the first tick stores every layer
        self.layers = np.zeros((self.block, len(LAYERS), h, w_), np.uint16)  # class images
        self.changed = np.zeros((self.block, len(LAYERS)), np.bool_)
        self.scales = np.array(recorder.scales, np.int64)
        self.levels = np.array([n_levels(k, scale) for k, scale in enumerate(recorder.scales)], np.int64)

    def buffers(self, n_ticks: int) -> tuple:
        if n_ticks > self.block:
            raise ValueError(f"record at most {self.block} ticks per engine step")
        return (self.pos, self.modes, self.payload, self.counters, self.last, self.layers, self.changed, self.scales,
                self.levels)  # fmt: skip

    def take(self, tick0: int, ran: int, seconds: float) -> None:
        """Hand the `ran` ticks just run (from tick0) to the recorder."""
        layers = {}
        for k, name in enumerate(LAYERS):
            rows = np.flatnonzero(self.changed[:ran, k])
            if len(rows):
                layers[name] = (tick0 + rows, self.layers[rows, k])  # class images; fancy indexing copies
        n = self.pos.shape[1]
        self.recorder.add(Block(
            ticks=np.arange(tick0, tick0 + ran), xy=cell_centres(self.pos[:ran]).astype(np.float32),
            modes=self.modes[:ran].copy(), payload=self.payload[:ran].copy(), present=np.ones((ran, n), bool),
            counters=self.counters[:ran].copy(), tick_ms=np.full(ran, seconds * 1000 / max(ran, 1)),
            rejected=np.zeros(ran), layers=layers,
        ))  # fmt: skip


def run_meta(scenario, world: GridWorld, run_id: str, until: str, runtime: str) -> dict:
    """What a reader needs to interpret the recording without the scenario file."""
    return {"run_id": run_id, "runtime": runtime, "scenario": scenario.describe(), "name": scenario.name,
            "controller": scenario.controller, "agents": scenario.agents, "seed": scenario.seed, "until": until,
            "total": world.total, "reachable_cells": world.reachable, "grid": list(world.layout.shape),
            "physics": scenario.physics.mode}  # fmt: skip


def default_blueprint():
    import rerun.blueprint as rrb

    plots = [rrb.TimeSeriesView(origin=f"/metrics/{name}", name=name.replace("_", " "))
             for name in ("delivered", "optimal_share", "agents_alive")]  # fmt: skip
    # the empty slots ("absent") stay in the recording but not in the plot: a world with 64 slots and
    # 3 agents would otherwise show little else
    plots.append(rrb.TimeSeriesView(origin="/metrics/agents", name="agents per state",
                                    contents=["$origin/**", f"- $origin/{STATES[ABSENT]}"]))  # fmt: skip
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Spatial2DView(origin="/world", name="grid"),
            rrb.Vertical(*plots),
            column_shares=[3, 2],
        ),
        collapse_panels=True,
    )


class Recorder:
    """Writes one run to an .rrd file (and, optionally, to a live viewer)."""

    def __init__(self, path: str | Path, world: GridWorld, meta: dict, viewer: str | None = None,
                 flush_every: int = 256):  # fmt: skip
        import rerun as rr

        self.rr = rr
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.world = world
        self.flush_every = flush_every
        self.rec = rr.RecordingStream("swarm", recording_id=str(meta.get("run_id", "run")))
        self._flush = stream_to(rr, self.rec, str(self.path), viewer, default_blueprint())
        self.meta = {"format": FORMAT_VERSION, **meta, "versions": software_versions()}
        self._blocks: list[Block] = []
        self._held = 0  # ticks in the blocks not yet flushed
        self._last: dict[str, np.ndarray] = {}
        # per layer kind (swarm.recording.layer_classes): the value that gets the last class
        self.scales = (max(1, int(world.layout.bfs.max())), 0, max(1, int(world.layers[L_RES].max())))
        self._log_static()
        self._flush(self.rec, timeout_sec=0)  # the meta and the map on disk now: a killed run's file still has them

    # ------------------------------------------------------------------ static

    def _log_static(self) -> None:
        rr, rec, w = self.rr, self.rec, self.world
        rec.log("run/meta", rr.AnyValues(meta=json.dumps(self.meta)), rr.TextDocument(json.dumps(self.meta, indent=1)),
                static=True)  # fmt: skip
        h, w_ = w.layout.shape
        walls = np.where(w.layout.obstacles[..., None], [40, 40, 48, 255], [235, 235, 228, 255]).astype(np.uint8)
        rec.log("world/obstacles", rr.Image(walls, color_model="RGBA", draw_order=0.0), static=True)
        fmt = rr.components.ImageFormat(width=w_, height=h, channel_datatype="U16")
        for kind, name in enumerate(LAYERS):
            rec.log(f"world/{name}", _annotation_context(kind, self.scales[kind]),
                    rr.SegmentationImage.from_fields(format=fmt, opacity=1.0, draw_order=float(kind + 1)),
                    static=True)  # fmt: skip
        r, c = w.base
        rec.log("world/base", rr.Points2D([[c + 0.5, r + 0.5]], radii=0.5, colors=[[220, 30, 30]], labels=["base"],
                                          draw_order=8.0), static=True)  # fmt: skip
        radius = w.scenario.physics.diameter / 2 if w.bodies.physical else 0.3
        rec.log("world/agents", rr.AnnotationContext([(i, name, colour) for i, (name, colour)
                                                      in enumerate(zip(STATES, STATE_COLOURS, strict=True))]),
                rr.Points2D.from_fields(radii=[radius], show_labels=False, draw_order=9.0), static=True)  # fmt: skip
        for name, colour in zip(STATES, STATE_COLOURS, strict=True):  # plot lines in the agents' colours
            rec.log(f"metrics/agents/{name}", rr.SeriesLines(colors=[colour], names=[name]), static=True)

    # -------------------------------------------------------------------- ticks

    def capture(self, tick: int, present: np.ndarray | None = None, tick_ms: float = 0.0,
                rejected: int = 0) -> None:  # fmt: skip
        """Take tick `tick` (just resolved) from the world: cheap copies only."""
        w = self.world
        n = len(w.pos)
        layers = {}
        for kind, (name, index) in enumerate(LAYERS.items()):
            layer = w.layers[index]
            last = self._last.get(name)
            if last is None or not np.array_equal(layer, last):
                self._last[name] = layer.copy()
                layers[name] = (np.array([tick]), class_images(kind, self._last[name][None], self.scales[kind]))
        self.add(Block(
            ticks=np.array([tick]), xy=w.body_xy[None].astype(np.float32), modes=w.acts[None, :, A_MODE].copy(),
            payload=w.payload[None].copy(), present=(np.ones(n, bool) if present is None else present.copy())[None],
            counters=w.counters[None].copy(), tick_ms=np.array([tick_ms]), rejected=np.array([rejected]),
            layers=layers,
        ))  # fmt: skip

    def add(self, block: Block) -> None:
        self._blocks.append(block)
        self._held += len(block.ticks)
        if self._held >= self.flush_every:
            self.flush()

    def flush(self) -> None:
        if not self._blocks:
            return
        rr, rec, blocks = self.rr, self.rec, self._blocks
        self._blocks, self._held = [], 0
        ticks = np.concatenate([b.ticks for b in blocks]).astype(np.int64)
        counters = np.concatenate([b.counters for b in blocks])
        payload = np.concatenate([b.payload for b in blocks])
        present = np.concatenate([b.present for b in blocks])
        states = agent_states(np.concatenate([b.modes for b in blocks]), payload, present)
        optimal = counters[:, C_OPTIMAL]
        metrics = {"delivered": counters[:, C_DELIVERED], "in_transit": payload.sum(axis=1),
                   "explored_cells": counters[:, C_EXPLORED], "optimal_cells": optimal,
                   "optimal_share": optimal / self.world.reachable, "agents_alive": present.sum(axis=1),
                   "tick_ms": np.concatenate([b.tick_ms for b in blocks]),
                   "rejected_messages": np.concatenate([b.rejected for b in blocks])}  # fmt: skip
        index = [rr.TimeColumn("tick", sequence=ticks)]
        for name in METRICS:
            scalars = np.asarray(metrics[name], dtype=np.float64)
            rec.send_columns(f"metrics/{name}", indexes=index, columns=rr.Scalars.columns(scalars=scalars))
        for s, name in enumerate(STATES):
            counts = (states == s).sum(axis=1).astype(np.float64)
            rec.send_columns(f"metrics/agents/{name}", indexes=index, columns=rr.Scalars.columns(scalars=counts))
        n = states.shape[1]
        if n:
            xy = np.concatenate([b.xy for b in blocks]).reshape(-1, 2)
            rec.send_columns("world/agents", indexes=index, columns=rr.Points2D.columns(
                positions=xy, class_ids=states.ravel()).partition([n] * len(ticks)))  # fmt: skip
        for name in LAYERS:
            changes = [b.layers[name] for b in blocks if name in b.layers]
            if changes:
                ticks_changed = np.concatenate([t for t, _ in changes]).astype(np.int64)
                classes = np.concatenate([snap for _, snap in changes])
                rec.send_columns(f"world/{name}", indexes=[rr.TimeColumn("tick", sequence=ticks_changed)],
                                 columns=rr.SegmentationImage.columns(
                                     buffer=classes.reshape(len(classes), -1).view(np.uint8)))  # fmt: skip
        self._flush(rec, timeout_sec=0)  # rerun's batches too, not waited for: a kill loses at most `flush_every` ticks

    def close(self, summary: dict | None = None) -> None:
        """Flush what is left, store the printed summary, close the file."""
        self.flush()
        if summary is not None:
            self.rec.log("run/summary", self.rr.AnyValues(summary=json.dumps(summary)), static=True)
        self._flush(self.rec)
        self.rec.disconnect()


# ------------------------------------------------------------------ colouring


@functools.cache
def _annotation_context(kind: int, scale: int):
    """What colours (and names) a layer's classes; class 0 is transparent.  Made
    once per process and layer: rerun converts class descriptions slowly (~65 µs each)."""
    import rerun as rr

    none = (0, "none", (0, 0, 0, 0))
    if kind == K_TRAILS:
        return rr.AnnotationContext([none, *((k + 1, f"trail id mod {len(TAB20)} = {k}", (*map(int, c[:3]), 230))
                                             for k, c in enumerate(TAB20))])  # fmt: skip
    legend = [none]
    for level in range(n_levels(kind, scale)):
        low, high = level_range(kind, level, scale)
        text = f"{low}" if low == high else f"{low}-{high}"
        if kind == K_MARKS:  # viridis from the base (0) to the farthest cell
            legend.append((level + 1, f"mark {text}", (*map(int, VIRIDIS[low * 255 // scale][:3]), 200)))
        else:  # resources: opacity rises with the quantity left
            legend.append((level + 1, f"{text} units", (250, 170, 20, 60 + high * 195 // scale)))
    return rr.AnnotationContext(legend)


def _hex(colours: str) -> np.ndarray:
    return np.array([[int(c[i : i + 2], 16) for i in (0, 2, 4)] + [255] for c in colours.split()], dtype=np.uint8)


# viridis at 9 evenly spaced points, interpolated to 256 levels (no matplotlib import on the hot path)
_VIRIDIS_ANCHORS = _hex("440154 472d7b 3b528b 2c728e 21918c 28ae80 5ec962 addc30 fde725").astype(np.float64)
VIRIDIS = np.stack([np.interp(np.linspace(0, 8, 256), np.arange(9), _VIRIDIS_ANCHORS[:, k]) for k in range(4)],
                   axis=1).astype(np.uint8)  # fmt: skip
TAB20 = _hex("1f77b4 aec7e8 ff7f0e ffbb78 2ca02c 98df8a d62728 ff9896 9467bd c5b0d5 "
             "8c564b c49c94 e377c2 f7b6d2 7f7f7f c7c7c7 bcbd22 dbdb8d 17becf 9edae5")  # fmt: skip


def open_for_server(server, path, viewer: str | None) -> Recorder:
    """The recorder of a world process's grid run (swarm.world_process lends it to the server)."""
    meta = run_meta(server.scenario, server.world, server.keys.run, server.until, server.mode)
    meta["resumed_at"] = server.tick if server.resumed else None
    return Recorder(path, server.world, meta, viewer=viewer)
