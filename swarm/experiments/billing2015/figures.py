"""`swarm experiment dft-figures`: the figures of Billing, Lowe & Sandamirskaya (2015) drawn from runs of the
dft controller.

- `motivation.png` (the paper's Figure 12): the four motivation fields when planning completes in one case-3
  run, with the start, the goal and the walls;
- `activity.png` (Figures 10 and 11): that run's motivation activity at four places it passed, for each
  elementary behaviour, over the whole run, the maximum of each intention field below, and its path;
- `planning.png` (section 6.2, "Dijkstra-like"): planning time against the A* path length over the Z-maze's
  pairs, with a least-squares line and Spearman's rho;
- `velocity.png` (Figure 14): speed and wheel speeds of that case-3 run, the obstacle's time in grey;
- `paths.png` (Figure 9): case-2 paths in the large maze, low and high noise.

Planning is complete at the first tick some intention field's output exceeds 0.5 within 15 cm of the robot
(the robot starts to move: the paper's t = 210 of Figure 12; the goal's own intention forms at once); the
plan reaches the robot at the first tick a motivation field is above zero within 15 cm of it.
Its runs take seeds from one of the protocol's ranges (swarm/experiments/protocol.py): development, to look
at, or confirmation, for the numbers docs/dft.md quotes.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from swarm.core.errors import ScenarioError
from swarm.core.plots import pyplot, save_figure
from swarm.experiments import stats as S
from swarm.experiments.billing2015.carrot import LARGE_HEADING, random_pairs, zmaze_pairs
from swarm.experiments.billing2015.dft import CASE3_BOXES, CASE3_GOAL, CASE3_START, classify
from swarm.experiments.protocol import CONFIRMATION_SEEDS, DEVELOPMENT_SEEDS
from swarm.experiments.runner import Outputs, batch_run

EBS = ("N", "S", "W", "E")
EB_COLOUR = {"N": "#d33", "S": "#37c", "W": "#3a3", "E": "#c80"}
INTENTION_THRESHOLD = 0.5  # f(u_I) above this: an intention has formed, the robot moves
NEAR = 15  # cells (15 cm): an intention this close to the robot is one it acts on
PLAN_CAP = 1500  # ticks a planning run may take at most (the Z-maze's plans complete in a few hundred)
# The paper's Figures 10-12 come from one case-3 run with a full obstacle appearing at t = 336 (its text); how
# long it stayed the paper does not say: ours stays the longest t_p of case 3's range.
REPLAN_APPEAR, REPLAN_DURATION = 336, 500
SNAPSHOT_EVERY = 4  # ticks between the motivation snapshots the four places are read from
PATH_EVERY = 4
CASE2_PAIRS = 3  # the paper's Figure 9: six runs, three pairs at low and high noise
PLANNING_FIELDS = ["pair", "start_x", "start_y", "goal_x", "goal_y", "seed", "optimal_length", "plan_reached_tick",
                   "planning_ticks"]  # fmt: skip
RUN_FIELDS = ["figure", "scenario", "noise", "pair", "seed", "start_x", "start_y", "goal_x", "goal_y",
              "planning_ticks", "route", "reached", "ticks", "ticks_to_goal", "path_length", "optimal_length",
              "collisions", "wall_seconds"]  # fmt: skip


def _engine(s):
    from swarm.engines.arena import ArenaEngine

    engine = ArenaEngine(s)
    return engine, engine.controllers[0]


def _cell(c, xy) -> tuple[int, int]:
    """The (row, col) of the field cell under point xy of controller c."""
    j, i = c._cell(float(xy[0]), float(xy[1]))
    return int(np.clip(round(j), 0, c.shape[0] - 1)), int(np.clip(round(i), 0, c.shape[1] - 1))


def _motivation(c) -> np.ndarray:
    return np.stack([c.engine.u(f"M_{d}") for d in EBS]).astype(np.float32)


def _near(c, xy, kind: str, read, level: float) -> bool:
    """Some `kind` field (read by `read`: outputs or activations) above `level` within NEAR cells of xy."""
    j, i = _cell(c, xy)
    rows, cols = slice(max(j - NEAR, 0), j + NEAR + 1), slice(max(i - NEAR, 0), i + NEAR + 1)
    return any(float(read(f"{kind}_{d}")[rows, cols].max()) > level for d in EBS)


def _intending(c, xy) -> bool:
    """An intention has formed near the robot: some I field's output above threshold within NEAR cells."""
    return _near(c, xy, "I", c.engine.output, INTENTION_THRESHOLD)


def run_planning(job: tuple) -> dict:
    """One Z-maze pair at low noise until planning completes (or PLAN_CAP ticks)."""
    from swarm.engines.goals import optimum_planner
    from swarm.scenario import load_scenario

    _, pair, sx, sy, gx, gy, seed = job
    s = load_scenario("zmaze").with_overrides(controller="dft", start=(sx, sy, 0.0), goal=(gx, gy), noise="low",
                                              seed=seed, max_ticks=PLAN_CAP)  # fmt: skip
    optimal = optimum_planner(s.size, s.walls).plan((sx, sy), (gx, gy))[0]
    engine, c = _engine(s)
    reached, planned = None, None
    while planned is None and not engine.done():
        engine.step()
        if reached is None and _near(c, engine.world.pose[0, :2], "M", c.engine.u, 0.0):
            reached = engine.tick
        if _intending(c, engine.world.pose[0, :2]):
            planned = engine.tick
    return {"kind": "planning", "pair": pair, "start_x": sx, "start_y": sy, "goal_x": gx, "goal_y": gy,
            "seed": seed, "optimal_length": round(float(optimal), 4), "plan_reached_tick": reached,
            "planning_ticks": planned}  # fmt: skip


def run_replanning(job: tuple) -> dict:
    """The case-3 run of Figures 10-12 and 14: a full obstacle across the north route at REPLAN_APPEAR."""
    from dataclasses import replace

    from swarm.scenario import load_scenario
    from world_server.arena.scenario import Obstacle

    _, seed, max_ticks = job
    s = load_scenario("zmaze").with_overrides(controller="dft", start=CASE3_START, goal=CASE3_GOAL, noise="low",
                                              seed=seed, max_ticks=max_ticks)  # fmt: skip
    box = Obstacle(CASE3_BOXES["full"], appear=REPLAN_APPEAR, vanish=REPLAN_APPEAR + REPLAN_DURATION,
                   colour=(150, 110, 70), name="full")  # fmt: skip
    s = replace(s, obstacles=(*s.obstacles, box))
    engine, c = _engine(s)
    w = engine.world
    xy, wheels, intentions, snaps = [w.pose[0, :2].copy()], [], [], [_motivation(c).astype(np.float16)]
    planned, plan_fields = None, None
    while not engine.done():
        engine.step()
        xy.append(w.pose[0, :2].copy())
        wheels.append(c.last_wheels.copy())
        intentions.append(list(c.intentions().values()))
        if engine.tick % SNAPSHOT_EVERY == 0:
            snaps.append(_motivation(c).astype(np.float16))
        if planned is None and _intending(c, engine.world.pose[0, :2]):
            planned, plan_fields = engine.tick, _motivation(c)
    xy = np.array(xy)
    if plan_fields is None:  # a short run (smoke): the fields at its end
        plan_fields = _motivation(c)
    # four places the robot passed, at 0, 1/3, 2/3 and the end of its run (the paper's locations 1-4)
    ticks = len(xy) - 1
    at = [0, ticks // 3, 2 * ticks // 3, ticks]
    cells = [_cell(c, xy[t]) for t in at]
    stack = np.stack(snaps)  # (snapshots, EB, rows, cols)
    rows = np.array([j for j, _ in cells])
    cols = np.array([i for _, i in cells])
    places = stack[:, :, rows, cols].astype(np.float32)  # (snapshots, EB, place)
    summary = engine.summary()
    robot = summary["robots"][0]
    return {"kind": "replanning", "seed": seed, "planning_ticks": planned, "route": classify(xy[1:, 1]),
            "reached": robot["reached"], "ticks": summary["ticks"], "ticks_to_goal": robot["ticks_to_goal"],
            "path_length": robot["path_length"], "optimal_length": robot["optimal_length"],
            "collisions": robot["collisions"], "wall_seconds": summary["wall_seconds"],
            "xy": xy.astype(np.float32), "speed": np.hypot(*np.diff(xy, axis=0).T) / s.control_period,
            "wheels": np.array(wheels).reshape(-1, 2), "intentions": np.array(intentions).reshape(-1, 4),
            "plan_fields": plan_fields, "walls": c.walls.copy(), "size": s.size, "place_ticks": at,
            "place_xy": xy[at], "places": places, "snapshot_ticks": np.arange(len(snaps)) * SNAPSHOT_EVERY,
            "control_period": s.control_period}  # fmt: skip


def run_case2(job: tuple) -> dict:
    """One large-maze pair (Figure 9)."""
    from swarm.scenario import load_scenario

    _, noise, pair, sx, sy, gx, gy, seed, max_ticks = job
    s = load_scenario("large-maze").with_overrides(controller="dft", start=(sx, sy, LARGE_HEADING), goal=(gx, gy),
                                                   noise=noise, seed=seed, max_ticks=max_ticks)  # fmt: skip
    engine, c = _engine(s)
    w = engine.world
    path, planned = [w.pose[0, :2].copy()], None
    while not engine.done():
        engine.step()
        if planned is None and _intending(c, engine.world.pose[0, :2]):
            planned = engine.tick
        if engine.tick % PATH_EVERY == 0:
            path.append(w.pose[0, :2].copy())
    path.append(w.pose[0, :2].copy())
    summary = engine.summary()
    robot = summary["robots"][0]
    return {"kind": "case2", "noise": noise, "pair": pair, "seed": seed, "start_x": sx, "start_y": sy,
            "goal_x": gx, "goal_y": gy, "planning_ticks": planned, "reached": robot["reached"],
            "ticks": summary["ticks"], "ticks_to_goal": robot["ticks_to_goal"], "path_length": robot["path_length"],
            "optimal_length": robot["optimal_length"], "collisions": robot["collisions"],
            "wall_seconds": summary["wall_seconds"], "path": np.array(path, np.float32)}  # fmt: skip


def run_job(job: tuple) -> dict:
    return {"case2": run_case2, "replanning": run_replanning, "planning": run_planning}[job[0]](job)


# ------------------------------------------------------------------ figures


def _floor(ax, walls: np.ndarray, size) -> None:
    ax.imshow(np.ma.masked_where(~walls, walls), origin="lower", extent=(0, size[0], 0, size[1]), cmap="copper",
              vmin=0, vmax=2, interpolation="nearest")  # fmt: skip
    ax.set(xlim=(0, size[0]), ylim=(0, size[1]), aspect="equal", xlabel="x (m)", ylabel="y (m)")


def plot_motivation(run: dict, seed_note: str, path: Path) -> None:
    """Figure 12: the four M fields when planning completes; supra-threshold activity is the plan."""
    plt = pyplot()
    size, fields = run["size"], run["plan_fields"]
    fig, axes = plt.subplots(1, 4, figsize=(17, 4.6), layout="constrained")
    lim = 10.0  # the recording's range (recording.py); stronger activity saturates
    for ax, d, u in zip(axes, EBS, fields, strict=True):
        im = ax.imshow(u, origin="lower", extent=(0, size[0], 0, size[1]), cmap="RdBu_r", vmin=-lim, vmax=lim)
        ax.contour(np.linspace(0, size[0], u.shape[1]), np.linspace(0, size[1], u.shape[0]), u, levels=[0],
                   colors="k", linewidths=0.6)  # fmt: skip
        ax.plot(*CASE3_START[:2], "o", mfc="w", mec="k", ms=7)
        ax.plot(*CASE3_GOAL, "x", c="w", mew=2, ms=8)
        ax.set(title=f"M {d}", xlabel="x (m)", ylabel="y (m)")
    fig.colorbar(im, ax=axes, shrink=0.8, label="activation u")
    tick = run["planning_ticks"]
    when = f"t = {tick}, planning complete" if tick is not None else f"t = {run['ticks']} (planning not complete)"
    fig.suptitle(f"Motivation fields at {when} (the paper's Figure 12: t = 210); black: u = 0; "
                 f"case-3 start (circle) and goal (cross); {seed_note}", fontsize=10)  # fmt: skip
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_activity(run: dict, seed_note: str, path: Path) -> None:
    """Figures 10 and 11: M activity at four places over time, the intentions' maxima, and the path."""
    plt = pyplot()
    fig = plt.figure(figsize=(14, 10))
    grid = fig.add_gridspec(5, 2, width_ratios=(2.2, 1))
    t = run["snapshot_ticks"]
    appear, vanish = REPLAN_APPEAR, REPLAN_APPEAR + REPLAN_DURATION
    for k in range(4):
        ax = fig.add_subplot(grid[k, 0])
        for e, d in enumerate(EBS):
            ax.plot(t, run["places"][:, e, k], c=EB_COLOUR[d], lw=1, label=d)
        ax.axvspan(appear, vanish, color="#ccc", alpha=0.6, lw=0)
        ax.axhline(0, c="k", lw=0.5)
        if run["planning_ticks"] is not None:
            ax.axvline(run["planning_ticks"], c="k", ls=":", lw=1)
        ax.set(ylabel=f"location {k + 1}\nu_M", xlim=(0, max(len(run["speed"]), 1)))
        if k == 0:
            ax.legend(ncol=4, fontsize=8, loc="upper right")
            ax.set_title(f"Motivation at four places the robot passed (t = {', '.join(map(str, run['place_ticks']))}"
                         "); grey: obstacle present; dotted: planning complete", fontsize=9)  # fmt: skip
    ax = fig.add_subplot(grid[4, 0])
    ti = np.arange(1, len(run["intentions"]) + 1)
    for e, d in enumerate(EBS):
        ax.plot(ti, run["intentions"][:, e], c=EB_COLOUR[d], lw=1, label=d)
    ax.axvspan(appear, vanish, color="#ccc", alpha=0.6, lw=0)
    ax.set(xlabel="t (steps of 64 ms)", ylabel="max f(u_I)", xlim=(0, max(len(ti), 1)))
    ax = fig.add_subplot(grid[:, 1])
    _floor(ax, run["walls"], run["size"])
    x0, y0, x1, y1 = CASE3_BOXES["full"]
    ax.add_patch(plt.Rectangle((x0, y0), x1 - x0, y1 - y0, color="#999", alpha=0.6))
    ax.plot(run["xy"][:, 0], run["xy"][:, 1], c="#d33", lw=1)
    for k, (x, y) in enumerate(run["place_xy"]):
        ax.annotate(str(k + 1), (x, y), fontsize=12, fontweight="bold", ha="center", va="center",
                    bbox={"boxstyle": "circle", "fc": "w"})  # fmt: skip
    ax.plot(*CASE3_GOAL, "kx", ms=9, mew=2)
    ax.set_title(f"Path ({run['route']}; Figure 11); {seed_note}", fontsize=9)
    save_figure(fig, path)


def plot_velocity(run: dict, seed_note: str, path: Path) -> None:
    """Figure 14: forward speed and wheel speeds over time; the obstacle's time in grey."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(11, 4))
    t = np.arange(1, len(run["speed"]) + 1)
    ax.axvspan(REPLAN_APPEAR, REPLAN_APPEAR + REPLAN_DURATION, color="#ccc", alpha=0.6, lw=0, label="obstacle")
    ax.plot(t, run["speed"] * 100, c="k", lw=1.2, label="speed (pose change per step)")
    ax.plot(t, run["wheels"][:, 0] * 100, c="#37c", lw=0.7, alpha=0.8, label="left wheel")
    ax.plot(t, run["wheels"][:, 1] * 100, c="#d33", lw=0.7, alpha=0.8, label="right wheel")
    if run["planning_ticks"] is not None:
        ax.axvline(run["planning_ticks"], c="k", ls=":", lw=1, label="planning complete")
    ax.set(xlabel="t (steps of 64 ms)", ylabel="speed (cm/s)", xlim=(0, max(len(t), 1)),
           title=f"Case 3, full obstacle at t = {REPLAN_APPEAR} for {REPLAN_DURATION} steps, low noise: route "
                 f"{run['route']} (the paper's Figure 14); {seed_note}")  # fmt: skip
    ax.title.set_fontsize(9)
    ax.legend(fontsize=8, loc="upper right")
    save_figure(fig, path)


def plot_planning(rows: list[dict], rho: float, p: float, seed_note: str, path: Path) -> None:
    """Planning time against the A* path length: the paper's Dijkstra-like search."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4.6))
    ok = [r for r in rows if r["planning_ticks"] is not None and math.isfinite(r["optimal_length"])]
    x = np.array([r["optimal_length"] for r in ok], float)
    y = np.array([r["planning_ticks"] for r in ok], float)
    ax.scatter(x, y, s=16, c="#37c")
    if len(ok) >= 2 and np.ptp(x) > 0:
        slope, icpt = np.polyfit(x, y, 1)
        xs = np.linspace(x.min(), x.max(), 2)
        ax.plot(xs, slope * xs + icpt, c="#d33", label=f"{slope:.0f} steps/m + {icpt:.0f}")
        ax.legend(fontsize=8)
    ax.set(xlabel="A* path length L_o (m)", ylabel="planning time (steps of 64 ms)",
           title=f"Z-maze, low noise, {len(ok)} of {len(rows)} pairs planned: Spearman rho = {rho:.2f} "
                 f"(p = {p:.2g})\n{seed_note}")  # fmt: skip
    ax.title.set_fontsize(9)
    save_figure(fig, path)


def plot_paths(rows: list[dict], seed_note: str, path: Path) -> None:
    """Figure 9: case-2 paths over the large maze, one colour per pair, solid low noise, dashed high."""
    from agents.controllers.navigation.astar import occupancy
    from swarm.scenario import load_scenario

    plt = pyplot()
    s = load_scenario("large-maze")
    fig, ax = plt.subplots(figsize=(8, 8))
    _floor(ax, occupancy(s.size, 0.005, s.wall_rects(), s.wall_segments()), s.size)
    colours = plt.get_cmap("tab10")
    pairs = sorted({r["pair"] for r in rows})
    for r in rows:
        colour = colours(pairs.index(r["pair"]) % 10)
        style, marker = ("-", "D") if r["noise"] == "low" else ("--", "s")
        ax.plot(r["path"][:, 0], r["path"][:, 1], ls=style, c=colour, lw=1.2,
                label=f"pair {r['pair']}, {r['noise']} noise{'' if r['reached'] else ' (not reached)'}")  # fmt: skip
        ax.plot(r["path"][-1, 0], r["path"][-1, 1], marker, c=colour, ms=6)
        ax.plot(r["start_x"], r["start_y"], "o", c=colour, ms=7, mec="k")
        ax.plot(r["goal_x"], r["goal_y"], "x", c=colour, ms=9, mew=2)
    ax.legend(fontsize=7, loc="upper right")
    ax.set_title(f"Case 2 paths (the paper's Figure 9): start o, goal x, end diamond (low) / square (high noise);\n"
                 f"{seed_note}", fontsize=9)  # fmt: skip
    save_figure(fig, path)


# ------------------------------------------------------------------ running


def run_dft_figures(name: str, reps: int | None, jobs: int | None, seed: int, out: Path | None,
                    scenario: str | None = None, max_ticks: int | None = None,
                    progress: bool = True) -> dict:  # fmt: skip
    """`reps` Z-maze pairs for planning time against path length (default 20), min(reps, 3) large-maze
    pairs at low and high noise for the paths, one case-3 run for the fields and the velocity profile."""
    if scenario is not None:
        raise ScenarioError("command line", "--scenario", f"{name} draws the paper's mazes (zmaze, large-maze)")
    seeds = _seed_range(name, seed, seed + max(reps or 20, CASE2_PAIRS))
    reps = 20 if reps is None else reps
    if not 1 <= reps <= 100:
        raise ScenarioError("command line", "--reps", "zmaze has the paper's 100 pairs: --reps 1 to 100")
    out = Outputs(out, name)
    case2 = [
        ("case2", noise, *p, seed + p[0], max_ticks)
        for p in random_pairs("large-maze", min(reps, CASE2_PAIRS), seed)
        for noise in ("low", "high")
    ]
    work = [*case2, ("replanning", seed, max_ticks)]  # the long runs first: the pool's tail is short
    work += [("planning", *p, seed + p[0]) for p in zmaze_pairs()[:reps]]
    rows = batch_run(run_job, work, jobs=jobs, desc=name, progress=progress)
    planning = [r for r in rows if r["kind"] == "planning"]
    replan = next(r for r in rows if r["kind"] == "replanning")
    paths = [r for r in rows if r["kind"] == "case2"]
    out.runs(planning, PLANNING_FIELDS, file="planning.csv")
    table = [{"figure": {"case2": "paths", "replanning": "motivation, activity, velocity"}[r["kind"]],
              "scenario": "large-maze" if r["kind"] == "case2" else "zmaze", "noise": r.get("noise", "low"),
              **{k: r.get(k) for k in RUN_FIELDS if k not in ("figure", "scenario", "noise")}}
             for r in (*paths, replan)]  # fmt: skip
    out.runs(table, RUN_FIELDS)

    ok = [r for r in planning if r["planning_ticks"] is not None and math.isfinite(r["optimal_length"])]
    trend = S.spearman([r["optimal_length"] for r in ok], [r["planning_ticks"] for r in ok])  # nan below 3
    rho, p = trend.statistic, trend.p
    first, last = seed + 1, seed + reps
    plot_planning(planning, rho, p, f"{seeds} seeds {first}-{last} (seed + pair)", out / "planning.png")
    note = f"{seeds} seed {seed}"
    plot_motivation(replan, note, out / "motivation.png")
    plot_activity(replan, note, out / "activity.png")
    plot_velocity(replan, note, out / "velocity.png")
    plot_paths(paths, f"{seeds} seeds {seed + 1}-{seed + min(reps, CASE2_PAIRS)} (seed + pair)",
               out / "paths.png")  # fmt: skip

    summary, md = _report(planning, ok, replan, paths, rho, p, seed, reps, max_ticks, seeds)
    result = out.finish(summary, md)
    result["runs"] = len(rows)
    return result


def _seed_range(name: str, first: int, last: int) -> str:
    """Which of the protocol's ranges holds every seed from `first` to `last`; refused if none does."""
    for label, pool in (("development", DEVELOPMENT_SEEDS), ("confirmation", CONFIRMATION_SEEDS)):
        if first in pool and last in pool:
            return label
    raise ScenarioError("command line", "--seed", f"{name} uses seeds {first} to {last}: they must lie in one range, "
                        "development (0 to 9999) or confirmation (10000 to 19999)")  # fmt: skip


def _report(planning: list[dict], ok: list[dict], replan: dict, paths: list[dict], rho: float, p: float,
            seed: int, reps: int, max_ticks: int | None, seeds: str) -> tuple[list[dict], str]:  # fmt: skip
    """summary.csv's rows and table.md's text."""
    first, last = seed + 1, seed + reps
    ticks = np.array([r["planning_ticks"] for r in ok], float)
    lengths = [r["optimal_length"] for r in ok]
    rho_ci, slope = S.spearman_ci(lengths, ticks, seed), S.slope_ci(lengths, ticks, seed)
    summary = [{"figure": "planning", "pairs": len(planning), "planned": len(ok),
                "planning_ticks_median": float(np.median(ticks)) if len(ok) else None,
                "spearman_rho": round(rho, 3) if math.isfinite(rho) else None,
                "spearman_p": float(f"{p:.3g}") if math.isfinite(p) else None,
                "spearman_rho_low": _round(rho_ci.low), "spearman_rho_high": _round(rho_ci.high),
                "ticks_per_metre": _round(slope.value), "ticks_per_metre_low": _round(slope.low),
                "ticks_per_metre_high": _round(slope.high)},
               {"figure": "replanning", "seed": seed, "planning_ticks": replan["planning_ticks"],
                "route": replan["route"], "reached": replan["reached"], "ticks_to_goal": replan["ticks_to_goal"]},
               {"figure": "paths", "runs": len(paths), "reached": sum(bool(r["reached"]) for r in paths)}]  # fmt: skip
    lines = "\n".join(f"| {r['pair']} | {r['optimal_length']:.3f} | {r['plan_reached_tick']} | {r['planning_ticks']} |"
                      for r in planning)  # fmt: skip
    md = (f"# Figures of Billing et al. (2015) from the dft controller\n\n{seeds.capitalize()} seeds: the planning "
          f"runs {first}-{last}, the case-3 run {seed}, the case-2 runs {seed + 1}-{seed + min(reps, CASE2_PAIRS)}; "
          f"at most {max_ticks or 3000} steps a case-2 or case-3 run.\n\n"
          f"## Planning time against path length (planning.png)\n\n{len(ok)} of {len(planning)} Z-maze pairs "
          f"planned at low noise; Spearman rho = {rho:.3f} (95% CI {_interval(rho_ci)}, p = {p:.3g}) between A*'s "
          f"L_o and the ticks until an intention formed; least-squares slope {slope.text()} ticks per metre.\n\n"
          f"| pair | L_o (m) | plan reaches the robot (tick) | planning complete (tick) |\n"
          f"|---|---|---|---|\n{lines}\n\n"
          f"## Case 3 (motivation.png, activity.png, velocity.png)\n\nFull obstacle at t = {REPLAN_APPEAR} for "
          f"{REPLAN_DURATION} steps; planning complete at t = {replan['planning_ticks']}; route {replan['route']}; "
          f"reached: {replan['reached']} (tick {replan['ticks_to_goal']}).\n\n"
          f"## Case 2 (paths.png)\n\n{summary[2]['reached']} of {len(paths)} runs reached their goal.\n")  # fmt: skip
    return summary, md


def _round(x: float) -> float | None:
    return round(x, 3) if math.isfinite(x) else None


def _interval(e: S.Estimate) -> str:
    return f"[{e.low:.3f}, {e.high:.3f}]" if math.isfinite(e.low) else "n/a"
