"""`swarm experiment fingerprint-robustness`: fingerprint localization (Tapus, Battaglia & Siegwart
2006) on the `office` floor under conditions, each changing one thing from the declared parameter
set (agents/controllers/fingerprint/params.py) and the scout's specified sensors:

- camera: the camera's noise at k units, each colour channel off by a normal error of std 10 k
  levels and each sector's distance by one of std 0.05 k m, on both tours;
- odometry bias, compass bias: the odometry's and the compass's bias (a constant error per run,
  drawn from the seed within +-the level), on both tours;
- kidnap: partway through the localization tour the robot is carried to a far-away waypoint of the
  tour and goes on from there, its odometry not knowing (its filter keeps its belief and odometric
  position); recovery is the number of fingerprints from the kidnapping until the filter's top node
  is right for HOLD fingerprints on the map in a row, censored at the tour's end;
- spacing (the paper's delta-d, metres between fingerprints) and theta (the matching threshold), on
  both tours.

Each run maps on the mapping tour and localizes on the floor's first localization tour, `new-path` on
`office` (fingerprint.second_tours, fingerprint.localize_run);
the shares are fingerprint.localization_counts' (matching alone, the Markov filter over the links,
the paper's kind, and on the odometric grid).  Ground truth (the robot's true pose, the place zones)
scores the runs here; the kidnapper moves the robot between the route's waypoints.  The controller
sees neither.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from swarm.experiments.runner import Outputs, batch_run
from swarm.experiments.tapus2006.fingerprint import along, drive_tour, localization_tours, localize_run, tour_scenario

HOLD = 3  # fingerprints on the map in a row at a right node that count as recovered
ESTIMATORS = (("match_correct", "matching alone"), ("links_markov_correct", "Markov, links (paper's)"),
              ("markov_correct", "Markov, grid"))  # fmt: skip
CAMERA_COLOUR, CAMERA_RANGE = 10.0, 0.05  # one unit of camera noise: colour std (levels), distance std (m)


def camera(k: float) -> dict:
    return {"sensors": {"camera": {"noise": CAMERA_COLOUR * k, "range_noise": CAMERA_RANGE * k}}}


def odometry_bias(b: float) -> dict:
    return {"sensors": {"odometry": {"bias": b}}}


def compass_bias(deg: float) -> dict:
    return {"sensors": {"compass": {"bias": math.radians(deg)}}}


def spacing(d: float) -> dict:
    return {"table": {"spacing": d}}


def theta(t: float) -> dict:
    return {"table": {"theta": t}}


# name: (what a level sets, the levels, the declared level (the baseline), the level's unit)
CONDITIONS: dict[str, tuple[Any, tuple[float, ...], float, str]] = {
    "camera": (camera, (0.0, 2.0), 0.0, "units (colour std 10 levels, distance std 0.05 m)"),
    "odometry bias": (odometry_bias, (0.0, 0.1), 0.0, "relative, within +-"),
    "compass bias": (compass_bias, (0.0, 10.0), 0.0, "degrees, within +-"),
    "kidnap": (None, (1.0,), 1.0, "one kidnapping"),
    "spacing": (spacing, (0.15, 0.3, 0.45), 0.15, "m between fingerprints (delta-d)"),
    "theta": (theta, (0.35, 0.5, 0.65), 0.5, "matching threshold"),
}
BASELINE = "declared"


def kidnap_waypoints(route, seed: int) -> tuple[int, int]:
    """(a, b): the tour's first stretch ends at waypoint a, drawn from the seed in its second quarter; the
    second starts at waypoint b, the one after a (up to three quarters in) that lies farthest from it."""
    xy, n = np.asarray(route, np.float64), len(route)
    rng = np.random.default_rng([seed, 46])
    a = int(rng.integers(max(n // 4, 1), max(n // 2, 2)))
    later = np.arange(a + 1, max(3 * n // 4, a + 2))
    return a, int(later[np.argmax(np.hypot(*(xy[later] - xy[a]).T))])


def kidnapped(seed: int, leg: dict):
    """A second tour (fingerprint.localize_run's `second`) with a kidnapping partway: the route's waypoints
    up to a, then the robot carried to b and on to the end (kidnap_waypoints), one controller throughout.
    Into `leg`: the index of the first fingerprint after the kidnapping, and how far the robot was carried."""

    def drive(tour, topomap: dict) -> dict:
        route = tour.routes[tour.groups[0].route]
        a, b = kidnap_waypoints(route, seed)
        legs = replace(tour, routes={**tour.routes, "kidnap-before": tuple(route[: a + 1]),
                                     "kidnap-after": tuple(route[b:])})  # fmt: skip
        first = drive_tour(along(legs, "kidnap-before"), topomap)
        then = drive_tour(along(legs, "kidnap-after"), topomap, resume=first["controller"].snapshot())
        leg.update(kidnapped_at=len(first["matched"]), moved=float(math.dist(route[a], route[b])))
        joined = {k: np.concatenate([first[k], then[k]]) for k in ("truth", "matched", "believed", "believed_links")}
        return {**joined, "likelihoods": first["likelihoods"] + then["likelihoods"], "size": then["size"],
                "ticks": first["ticks"] + then["ticks"], "finished": then["finished"],
                "wall_seconds": first["wall_seconds"] + then["wall_seconds"]}  # fmt: skip

    return drive


def recovery(right: np.ndarray, start: int, hold: int = HOLD) -> tuple[int, bool]:
    """(fingerprints from the kidnapping at `start` to the first of `hold` on the map in a row that are right,
    counted from 1; whether it came): `right` is 1 right, 0 wrong, -1 off the map (skipped).  Not recovered:
    the fingerprints to the tour's end, censored."""
    after = right[start:]
    on = np.flatnonzero(after >= 0)
    ok = after[on] == 1
    if len(ok) >= hold:
        runs = np.lib.stride_tricks.sliding_window_view(ok, hold).all(axis=1)
        if runs.any():
            return int(on[np.argmax(runs)]) + 1, True
    return len(after), False


def robustness_job(job: tuple) -> dict:
    """One run: (floor, condition, level, seed, routes, second tour) -> a row."""
    name, condition, level, seed, routes, route = job
    change = {} if condition in (BASELINE, "kidnap") else CONDITIONS[condition][0](level)
    leg: dict = {}  # the kidnapped tour's own numbers: where the kidnapping came, how far the robot was carried
    second = kidnapped(seed, leg) if condition == "kidnap" else None
    _, c = localize_run(name, "low", seed, route, routes=routes, second=second, per_print=True, **change)
    shares = {key: round(c[right] / c["on_map"], 4) if c["on_map"] else math.nan
              for key, right in (("match_correct", "match_right"), ("links_markov_correct", "links_right"),
                                 ("markov_correct", "markov_right"))}  # fmt: skip
    row = {"scenario": name, "condition": condition, "level": level, "seed": seed, "map_nodes": c["map_nodes"],
           "fingerprints": c["fingerprints"], "on_map": c["on_map"], **shares, "chance": c["chance"]}  # fmt: skip
    if condition == "kidnap":
        at = leg["kidnapped_at"]
        (grid, grid_ok), (links, links_ok) = recovery(c["right"][:, 1], at), recovery(c["right"][:, 2], at)
        row |= {"kidnapped_at": at, "moved_m": round(leg["moved"], 2), "recovery_grid": grid,
                "recovered_grid": grid_ok, "recovery_links": links, "recovered_links": links_ok}  # fmt: skip
    return row | {"ticks": c["ticks"], "finished": c["finished"], "wall_seconds": c["wall_seconds"]}


def short_routes(floor, waypoints: int, route: str) -> dict:
    """Both tours cut to the mapping tour's first `waypoints` waypoints of `floor` (a loaded scenario):
    a quick run that stays on its map."""
    cut = tuple(floor.routes["mapping"][:waypoints])
    return {"mapping": cut, route: cut}


def run_robustness_experiment(which: str, scenario: str | None, reps: int | None, jobs: int | None, seed: int,
                              out: Path | None, progress: bool = True, conditions: tuple[str, ...] | None = None,
                              waypoints: int | None = None) -> dict:  # fmt: skip
    from swarm.experiments.protocol import DEVELOPMENT_SEEDS, is_confirmation

    name = scenario or "office"
    reps = reps or 3
    chosen = tuple(conditions or CONDITIONS)
    unknown = [c for c in chosen if c not in CONDITIONS]
    if unknown:
        raise ValueError(f"unknown condition {unknown[0]!r}; expected one of {', '.join(CONDITIONS)}")
    # a floor it cannot map, or without a second tour: one line
    floor = tour_scenario(name, "mapping", "low", seed)
    route = localization_tours(floor, name, which)[0]
    routes = short_routes(floor, waypoints, route) if waypoints else None
    seeds = range(seed, seed + reps)
    work = [(name, BASELINE, math.nan, s, routes, route) for s in seeds]
    work += [(name, c, lv, s, routes, route) for c in chosen for lv in CONDITIONS[c][1]
             if c == "kidnap" or lv != CONDITIONS[c][2] for s in seeds]  # fmt: skip
    rows = batch_run(robustness_job, work, jobs=jobs, desc=which, progress=progress)
    out = Outputs(out, which)
    out.runs(rows, fields=_fields(rows))
    summary = summarize(rows, chosen)
    out.runs(summary, file="summary.csv")
    band = "confirmation" if is_confirmation(seed) else "development" if seed in DEVELOPMENT_SEEDS else "other"
    md = table(summary, name, seeds, band, waypoints, route)
    plot(summary, rows, out / "plot.png")
    return out.finish(None, md)


def _fields(rows: list[dict]) -> list[str]:
    keys: list[str] = []
    for r in rows:
        keys += [k for k in r if k not in keys]
    return keys


def _level_rows(rows: list[dict], condition: str, level: float) -> list[dict]:
    """The runs of one condition's level; the declared level is the baseline runs."""
    if condition != "kidnap" and level == CONDITIONS[condition][2]:
        return [r for r in rows if r["condition"] == BASELINE]
    return [r for r in rows if r["condition"] == condition and r["level"] == level]


def summarize(rows: list[dict], chosen: tuple[str, ...]) -> list[dict]:
    """Per condition and level: each estimator's mean share with its 95% bootstrap interval over the runs, n,
    seeds; for the kidnapping the Kaplan-Meier median recovery (runs not recovered censored)."""
    from swarm.experiments.stats import kaplan_meier_median, mean_ci

    out = []
    for c in chosen:
        for level in CONDITIONS[c][1]:
            sel = _level_rows(rows, c, level)
            row: dict[str, Any] = {"condition": c, "level": level, "declared": c != "kidnap" and
                                   level == CONDITIONS[c][2], "n": len(sel),
                                   "seeds": " ".join(str(r["seed"]) for r in sel)}  # fmt: skip
            for key, _ in ESTIMATORS:
                e = mean_ci([r[key] for r in sel])
                row |= {key: round(e.value, 4), f"{key}_low": round(e.low, 4), f"{key}_high": round(e.high, 4)}
            if c == "kidnap":
                for f in ("grid", "links"):
                    t, done = [r[f"recovery_{f}"] for r in sel], [bool(r[f"recovered_{f}"]) for r in sel]
                    e = kaplan_meier_median(t, done)
                    row |= {f"recovery_{f}_median": e.value, f"recovery_{f}_low": e.low,
                            f"recovery_{f}_high": e.high, f"censored_{f}": sum(not d for d in done)}  # fmt: skip
            out.append(row)
    return out


def _ci(r: dict, key: str) -> str:
    if math.isnan(r[key]):
        return "–"
    if math.isnan(r[f"{key}_low"]):
        return f"{r[key]:.1%}"
    return f"{r[key]:.1%} [{r[f'{key}_low']:.1%}, {r[f'{key}_high']:.1%}]"


def _median(r: dict, f: str) -> str:
    m, lo, hi = (r[f"recovery_{f}_{k}"] for k in ("median", "low", "high"))
    text = "not reached" if math.isnan(m) else f"{m:.0f}"
    if not math.isnan(m) and not (math.isnan(lo) and math.isnan(hi)):
        text += f" [{'–' if math.isnan(lo) else f'{lo:.0f}'}, {'–' if math.isnan(hi) else f'{hi:.0f}'}]"
    return f"{text} ({r[f'censored_{f}']} of {r['n']} censored)"


def table(summary: list[dict], name: str, seeds: range, band: str, waypoints: int | None, route: str) -> str:
    tours = f"the mapping tour's first {waypoints} waypoints, twice" if waypoints else f"mapping, then `{route}`"
    lines = [f"# Fingerprint localization under conditions (Tapus et al. 2006), `{name}`\n",
             f"{len(seeds)} runs per condition level, {band} seeds {seeds.start}..{seeds.stop - 1}; {tours}.  "
             "Each condition changes one thing from the declared parameters (the declared level is the same "
             "runs in every condition).  Share of the second tour's fingerprints on the map at a right node, "
             "mean over runs [95% bootstrap interval].\n",
             "| condition | level | n | matching alone | Markov, links (paper's) | Markov, grid |",
             "|---|---|---|---|---|---|"]  # fmt: skip
    for r in summary:
        level = f"{r['level']:g}" + (" (declared)" if r["declared"] else "")
        lines.append(f"| {r['condition']} | {level} | {r['n']} | " +
                     " | ".join(_ci(r, k) for k, _ in ESTIMATORS) + " |")  # fmt: skip
    kid = [r for r in summary if r["condition"] == "kidnap"]
    if kid:
        r = kid[0]
        lines += ["\n| kidnapping: recovery in fingerprints | n | Markov, links (paper's) | Markov, grid |",
                  "|---|---|---|---|",
                  f"| Kaplan-Meier median [95%] | {r['n']} | {_median(r, 'links')} | "
                  f"{_median(r, 'grid')} |"]  # fmt: skip
    units = "; ".join(f"{c}: {spec[3]}" for c, spec in CONDITIONS.items())
    lines.append(f"\nLevels: {units}.  Recovery: fingerprints from the kidnapping to the first of {HOLD} in a "
                 "row (on the map) at a right node; a run that never gets there is censored at the tour's end.  "
                 "Seeds: the runs' seeds are in summary.csv.")  # fmt: skip
    return "\n".join(lines) + "\n"


def plot(summary: list[dict], rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sweeps = list(dict.fromkeys(r["condition"] for r in summary))
    fig, axes = plt.subplots(1, len(sweeps), figsize=(3.4 * len(sweeps), 3.8), squeeze=False)
    for ax, c in zip(axes[0], sweeps, strict=True):
        sel = [r for r in summary if r["condition"] == c]
        x = np.array([r["level"] for r in sel], np.float64)
        for i, (key, label) in enumerate(ESTIMATORS):
            y = np.array([r[key] for r in sel])
            err = np.array([[r[key] - r[f"{key}_low"], r[f"{key}_high"] - r[key]] for r in sel]).T
            shift = (i - 1) * 0.02 * (np.ptp(x) or 1.0)
            ax.errorbar(x + shift, y, yerr=np.nan_to_num(err), fmt="o-", ms=4, capsize=3, label=label)
        ax.set(title=c, xlabel=CONDITIONS[c][3] if len(CONDITIONS[c][3]) < 30 else "level", ylim=(0, 1.02))
        if c == "kidnap":
            ax.set_xticks(x, ["kidnapped"])
    axes[0][0].set_ylabel("share at the right node")
    axes[0][0].legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
