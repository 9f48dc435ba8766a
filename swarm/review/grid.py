"""`swarm report` for grid recordings: the summary rebuilt from the file, and plots (delivered,
share of optimal cells, agents per state against the tick)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from swarm.core.plots import plot_writer
from swarm.recording.grid import STATES


def grid_summary_from(rec) -> dict:
    """The run summary (keys of `swarm run --json`, plus the distributed ones
    when the run was distributed), rebuilt from the recorded series."""
    m = rec.meta
    ticks = rec.values("delivered")[0]
    delivered = int(rec.last("delivered"))
    optimal = int(rec.last("optimal_cells"))
    foraged, converged = delivered >= m["total"], optimal == m["reachable_cells"]
    finished = {"foraged": foraged, "converged": converged, "both": foraged and converged}[m["until"]]
    summary = {
        "scenario": m["name"], "controller": m["controller"], "agents": m["agents"], "seed": m["seed"],
        "until": m["until"], "iterations": int(ticks[-1]) + 1 if len(ticks) else 0, "finished": finished,
        "delivered": delivered, "total": m["total"], "in_transit": int(rec.last("in_transit")),
        "apf_optimal": converged, "optimal_cells": optimal, "explored_cells": int(rec.last("explored_cells")),
        "reachable_cells": m["reachable_cells"], "grid": m["grid"], "physics": m["physics"],
    }  # fmt: skip
    if m["runtime"] != "in-process":
        tick_ms = rec.values("tick_ms")[1]
        summary.update({
            "run_id": m["run_id"], "mode": m["runtime"], "rejected_messages": int(rec.last("rejected_messages")),
            "agents_peak": int(rec.values("agents_alive")[1].max(initial=0)),
            "tick_ms_p50": round(float(np.percentile(tick_ms, 50)), 3) if len(tick_ms) else 0.0,
            "tick_ms_p99": round(float(np.percentile(tick_ms, 99)), 3) if len(tick_ms) else 0.0,
        })  # fmt: skip
    return summary


def write_grid_plots(rec, out: Path) -> list[Path]:
    plt, save, written = plot_writer(out)
    title = f"{rec.meta['name']}: {rec.meta['controller']} x{rec.meta['agents']}, seed {rec.meta['seed']}"

    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(*rec.values("delivered"), label="delivered")
    ax.axhline(rec.meta["total"], color="grey", linestyle="--", label="total")
    ax.set(xlabel="tick", ylabel="units", title=f"Delivered — {title}")
    ax.legend()
    save(fig, "delivered.png")

    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(*rec.values("optimal_share"))
    ax.set(xlabel="tick", ylabel="share", ylim=(0, 1.02), title="Cells whose mark equals the BFS distance")
    save(fig, "optimal_share.png")

    fig, ax = plt.subplots(figsize=(6, 3.5))
    ticks = rec.values(f"agents/{STATES[0]}")[0]
    present = [s for s in STATES if s != "absent"]  # empty slots are not agents
    counts = [rec.values(f"agents/{s}")[1] for s in present]
    ax.stackplot(ticks, *counts, labels=present)
    ax.set(xlabel="tick", ylabel="agents", title="Agents per state")
    ax.legend(loc="upper right", fontsize="small")
    save(fig, "agent_states.png")
    return written
