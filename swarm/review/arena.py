"""`swarm report` for arena recordings: the summary rebuilt from the file, and
plots (trajectories over the floor plan, robots at their goals over time,
path length against the optimum)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np


def arena_summary_from(rec) -> dict:
    m = rec.meta
    ticks, in_goal = rec.values("robots/in_goal")
    _, lengths = rec.values("robots/path_length")
    _, collisions = rec.values("robots/collisions")
    _, finished = rec.values("robots/finished")
    n = m["agents"]
    if len(ticks) == 0:
        in_goal = lengths = collisions = finished = np.zeros((0, n))
    robots = _robot_rows(m, ticks, in_goal, lengths, collisions, finished)
    goals = [r for r in robots if r["goal"] is not None]
    ratios = [r["path_ratio"] for r in robots if r["path_ratio"] is not None]
    summary = {
        "scenario": m["name"],
        "kind": "arena",
        "controller": m["controller"],
        "agents": n,
        "seed": m["seed"],
        "noise": m["noise"],
        "runtime": m["runtime"],
        "ticks": int(ticks[-1]) + 1 if len(ticks) else 0,
        # with goals: all reached; without: the run went its full length (as the in-process summary)
        "finished": all(r["reached"] for r in goals)
        if goals
        else bool(len(ticks)) and int(ticks[-1]) + 1 >= m["max_ticks"],
        "reached": sum(r["reached"] for r in goals),
        "with_goal": len(goals),
        "sim_seconds": round((int(ticks[-1]) + 1 if len(ticks) else 0) * m["control_period"], 3),
        "mean_path_ratio": round(float(np.mean(ratios)), 4) if ratios else None,
        "collisions": int(rec.last("collisions")),
        "robots": robots,
    }
    summary["iterations"] = summary["ticks"]
    _add_runtime_fields(summary, rec, m)
    return summary


def _robot_rows(m: dict, ticks, in_goal, lengths, collisions, finished) -> list[dict]:
    """Each robot's line of the summary, from the meta and the per-robot series (one row a tick)."""
    robots = []
    for a in range(m["agents"]):
        goal = m["goals"][a]
        reached = bool(goal is not None and len(in_goal) and (in_goal[-1, a] > 0 or finished[-1, a] > 0))
        first = np.flatnonzero(in_goal[:, a] > 0) if len(in_goal) else np.zeros(0, int)
        lp = float(lengths[-1, a]) if len(lengths) else 0.0
        lo = m["optimal_lengths"][a]
        robots.append({
            "agent": a, "controller": m["controllers"][a], "start": [round(v, 4) for v in m["starts"][a]],
            "goal": None if goal is None else [round(v, 4) for v in goal], "reached": reached,
            "ticks_to_goal": int(ticks[first[0]]) + 1 if goal is not None and len(first) else None,
            "path_length": round(lp, 4), "optimal_length": None if lo is None else round(lo, 4),
            "path_ratio": round(lp / lo, 4) if reached and lo else None,
            "collisions": int(collisions[-1, a]) if len(collisions) else 0,
        })  # fmt: skip
    return robots


def _add_runtime_fields(summary: dict, rec, m: dict) -> None:
    """The fields that depend on the runtime: rejected actions in-process, else the world server's
    run id, mode, messages, peak agents and tick times."""
    if m["runtime"] == "in-process":
        summary["rejected_actions"] = int(rec.last("rejected_messages"))
    else:
        tick_ms = rec.values("tick_ms")[1]
        summary.update(
            {
                "run_id": m["run_id"],
                "mode": m["runtime"],
                "rejected_messages": int(rec.last("rejected_messages")),
                "agents_peak": int(rec.values("agents_alive")[1].max(initial=0)),
                "tick_ms_p50": round(float(np.percentile(tick_ms, 50)), 3) if len(tick_ms) else 0.0,
                "tick_ms_p99": round(float(np.percentile(tick_ms, 99)), 3) if len(tick_ms) else 0.0,
            }
        )


def write_arena_plots(rec, out: Path) -> list[Path]:
    from swarm.core.plots import plot_writer

    plt, save, written = plot_writer(out)
    m = rec.meta
    title = f"{m['name']}: {m['controller']} x{m['agents']}, seed {m['seed']}, noise {m['noise']}"

    fig, ax = plt.subplots(figsize=(6, 6))
    for wall in m.get("walls", []):
        x0, y0, x1, y1 = wall["coords"]
        colour = np.array(wall["colour"]) / 255
        if wall["shape"] == "rect":
            ax.add_patch(plt.Rectangle((x0, y0), x1 - x0, y1 - y0, color=colour, lw=0))
        else:
            ax.plot([x0, x1], [y0, y1], color=colour, lw=2)
    for o in m.get("obstacles", []):
        x0, y0, x1, y1 = o["rect"]
        ax.add_patch(plt.Rectangle((x0, y0), x1 - x0, y1 - y0, facecolor=np.array(o["colour"]) / 255,
                                   edgecolor="k", lw=0.5, alpha=0.9))  # fmt: skip
        if o["zone"]:
            ax.annotate(o["name"], ((x0 + x1) / 2, y1), ha="center", va="bottom", fontsize=7)
    _, xy = rec.values("positions")
    if len(xy):
        for a in range(xy.shape[1]):
            ax.plot(xy[:, a, 0], xy[:, a, 1], lw=1)
    for a, goal in enumerate(m["goals"]):
        if goal is not None:
            ax.plot(*goal, "x", color="k")
            ax.plot(*m["starts"][a][:2], "o", color="k", ms=3)
    size = m["scenario"]["size"]
    ax.set(xlim=(0, size[0]), ylim=(0, size[1]), aspect="equal", xlabel="x (m)", ylabel="y (m)",
           title=f"Trajectories — {title}")  # fmt: skip
    save(fig, "trajectories.png")

    fig, ax = plt.subplots(figsize=(6, 3.5))
    ticks, in_goal = rec.values("robots/in_goal")
    if len(ticks):
        ax.plot(ticks, in_goal.sum(axis=1), label="in the goal radius")
    ax.plot(*rec.values("reached"), label="finished (dwelt)")
    ax.set(xlabel="tick", ylabel="robots", title="Robots at their goals")
    ax.legend()
    save(fig, "goals.png")

    fig, ax = plt.subplots(figsize=(6, 3.5))
    _, lengths = rec.values("robots/path_length")
    if len(lengths):
        lo = [v if v is not None else math.nan for v in m["optimal_lengths"]]
        k = np.arange(lengths.shape[1])
        ax.bar(k - 0.2, lengths[-1], width=0.4, label="L_p")
        ax.bar(k + 0.2, lo, width=0.4, label="L_o (A*)")
    ax.set(xlabel="robot", ylabel="m", title="Path length against the optimum")
    ax.legend()
    save(fig, "path_lengths.png")
    return written
