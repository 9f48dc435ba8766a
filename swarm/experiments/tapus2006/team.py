"""`swarm experiment fingerprint-together`: N fingerprint robots map one floor
together over the `map` key space.

The floor is split into N stretches of the corridor; robot k drives its
stretch west to east and enters every room whose door is on it, north then
south (a survey: N = 1 drives all 16 rooms).  Every robot publishes its map's
changes each tick and merges the others' (agents.controllers.navigation.mapshare).
Robot 0's merged map covers the floor when each of the floor's 20 places has
a node in it, a node's place being where most of the fingerprints behind it
were taken (by whichever robot made it; ground truth, for judging only).
On another floor (--scenario) robot k of N drives the k-th of N stretches of
the floor's `mapping` route, and the floor's place zones judge the map.
Reported per N: ticks (and simulated seconds) until robot 0's map covers the
floor, the mean distance each robot had driven by then, robot 0's node count
at the end against a lone robot's, how many of its nodes came from others
and how many of the others' nodes it merged into its own, and how many
places it knows but never visited.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np

from swarm.core.errors import ScenarioError
from swarm.experiments.runner import Outputs, batch_run
from swarm.experiments.tapus2006.fingerprint import place_of, places

TEAMS = (1, 2, 4, 8)
FLOOR = 32.0
DOORS = [4 * j + 2.0 for j in range(8)]  # every room's door, north and south of the corridor


def survey_route(x0: float, x1: float) -> list[list[float]]:
    """Along the corridor from x0 to x1, into every room whose door lies in [x0, x1), north then south."""
    route = [[x0, 6.0]]
    for x in DOORS:
        if x0 <= x < x1 or (x1 >= FLOOR - 1 and x0 <= x):
            route += [[x, 6.7], [x, 7.6], [x, 9.4], [x, 7.6], [x, 6.7],
                      [x, 5.3], [x, 4.4], [x, 2.6], [x, 4.4], [x, 5.3]]  # fmt: skip
    route.append([x1, 6.0])
    return route


def team_toml(robots: int, base: str = "office") -> str:
    """The office floor with `robots` fingerprint scouts, robot k surveying the k-th stretch."""
    from swarm.scenario import BUNDLED_DIR

    text = (BUNDLED_DIR / f"{base}.toml").read_text()
    text = re.sub(r"\n\[\[group\]\]\n(?:(?!\[)[^\n]+\n)+", "\n", text, count=1)  # the file's one robot
    routes, groups = [], []
    for k in range(robots):
        x0 = 0.8 if k == 0 else FLOOR * k / robots + 0.8
        x1 = FLOOR - 0.8 if k == robots - 1 else FLOOR * (k + 1) / robots - 0.8
        routes.append(f"survey_{k} = {survey_route(x0, x1)}")
        groups.append(f'[[group]]\ncount = 1\ncontroller = "fingerprint"\nstart = [{x0}, 6.0, 0.0]\n'
                      f'route = "survey_{k}"\n')  # fmt: skip
    text = text.replace("[routes]\n", "[routes]\n" + "\n".join(routes) + "\n", 1)
    return text.rstrip("\n") + "\n\n" + "\n".join(groups)


def team_scenario(robots: int, noise: str, seed: int, floor: str | None = None):
    """The office with `robots` surveyors, or `floor` with robot k driving the k-th stretch of its mapping route."""
    from swarm.scenario import parse_arena_text

    if floor is not None:
        return floor_team(floor, robots).with_overrides(noise=noise, seed=seed)
    s = parse_arena_text(team_toml(robots), f"office, {robots} surveyors", "office-team")
    return s.with_overrides(noise=noise, seed=seed)


def stretches(route: tuple, robots: int) -> list[list[tuple[float, float]]]:
    """A route cut into `robots` consecutive stretches of equal length (any team fits any route), each
    stretch from its cut to the next through the route's waypoints between them."""
    pts = np.asarray(route, float)
    legs = np.maximum(np.hypot(*np.diff(pts, axis=0).T), 1e-9)
    along = np.concatenate([[0.0], np.cumsum(legs)])

    def at(d: float) -> tuple[float, float]:
        i = int(np.clip(np.searchsorted(along, d, side="right") - 1, 0, len(legs) - 1))
        x, y = pts[i] + (d - along[i]) / legs[i] * (pts[i + 1] - pts[i])
        return float(x), float(y)

    cuts = [along[-1] * k / robots for k in range(robots + 1)]
    return [[at(a), *(tuple(map(float, p)) for p, d in zip(pts, along, strict=True) if a < d < b), at(b)]
            for a, b in itertools.pairwise(cuts)]  # fmt: skip


def check_team_floor(floor: str, teams: tuple[int, ...]):
    """The floor --scenario names, checked for what the team needs: an arena floor with place zones (to judge
    the map by) and a 'mapping' route to share among the robots."""
    from swarm.scenario import load_scenario

    s = load_scenario(floor)
    if getattr(s, "kind", "grid") != "arena":  # a grid scenario has no kind field
        raise ScenarioError(floor, "kind", "fingerprint-together maps an arena floor")
    if not places(s):
        raise ScenarioError(floor, "zones", "fingerprint-together needs place zones ([[zone]] kind = \"place\", "
                            "rect = [...]) to judge the map by")  # fmt: skip
    if "mapping" not in s.routes:
        raise ScenarioError(floor, "routes", "fingerprint-together needs a 'mapping' route, split among the robots")
    route = np.asarray(s.routes["mapping"], float)
    if len(route) < 2 or not np.hypot(*np.diff(route, axis=0).T).sum() > 0:
        raise ScenarioError(floor, "routes.mapping", "fingerprint-together needs a mapping route of some length")
    return s


def floor_team(floor: str, robots: int):
    """`floor` with `robots` fingerprint robots (its first group's), robot k on the k-th stretch of its mapping
    route, facing along it."""
    s = check_team_floor(floor, (robots,))
    routes, groups = dict(s.routes), []
    for k, stretch in enumerate(stretches(s.routes["mapping"], robots)):
        (x0, y0), (x1, y1) = stretch[0], stretch[1]
        routes[f"survey_{k}"] = tuple(stretch)
        groups.append(replace(s.groups[0], count=1, controller="fingerprint", route=f"survey_{k}",
                              starts=((x0, y0, math.atan2(y1 - y0, x1 - x0)),), goals=None,
                              draw_goals=False))  # fmt: skip
    return replace(s, groups=tuple(groups), routes=routes)


def team_job(job: tuple) -> dict:
    from swarm.engines.arena import ArenaEngine

    robots, noise, seed, *floor = job
    s = team_scenario(robots, noise, seed, *floor)
    zones = places(s)
    engine = ArenaEngine(s)
    cs = engine.controllers
    counts = [dict() for _ in cs]  # per robot: its node -> place -> fingerprints
    covered_tick, covered_distance = None, None
    while not all(c.finished for c in cs) and engine.tick < 40_000:
        before = engine.world.pose[:, :2].copy()
        seen = [len(c.log) for c in cs]
        engine.step(1)
        for k, c in enumerate(cs):
            if len(c.log) > seen[k]:
                node_counts = counts[k].setdefault(c.believed, {})
                p = place_of(before[k], zones)
                node_counts[p] = node_counts.get(p, 0) + 1
        if covered_tick is None and len(known_places(cs[0], counts)) == len(zones):
            covered_tick = engine.tick
            covered_distance = float(np.mean(engine.world.path_length))
    mine = set()
    for node_counts in counts[0].values():
        mine |= set(node_counts)
    known = known_places(cs[0], counts)
    lead = cs[0].summary()["map"]
    return {"robots": robots, "noise": noise, "seed": seed, "ticks": engine.tick,
            "covered_tick": covered_tick if covered_tick is not None else "",
            "covered_seconds": round(covered_tick * s.control_period, 1) if covered_tick is not None else "",
            "covered_distance": round(covered_distance, 2) if covered_distance is not None else "",
            "places": len(zones), "places_known": len(known), "known_not_visited": len(known - mine),
            "nodes": lead["nodes"], "from_others": lead["from_others"], "merged_with_ours": lead["merged_with_ours"],
            "own_fingerprints": lead["fingerprints"], "rejected_shared": engine.refused_shared,
            "wall_seconds": round(engine.wall_seconds, 2)}  # fmt: skip


def known_places(lead, counts: list[dict]) -> set[int]:
    """Places of robot 0's nodes: its own by its fingerprints, copies by their maker's."""
    out = set()
    own: dict[int, dict] = {}  # robot 0's fingerprints by the node they stand in now (folds resolved)
    for node, tally in counts[0].items():
        mine = own.setdefault(lead.map.resolve(node), {})
        for p, n in tally.items():
            mine[p] = mine.get(p, 0) + n
    counts = [own, *counts[1:]]
    for i in range(len(lead.map.nodes)):
        if i in lead.map.folded:
            continue
        robot, node = lead.shared.origin.get(i, (0, i))
        tally = dict(counts[robot].get(node, {}))
        if robot != 0:  # a copy robot 0 has since observed at: its own fingerprints count too
            for p, n in counts[0].get(i, {}).items():
                tally[p] = tally.get(p, 0) + n
        if tally:
            out.add(max(tally, key=tally.get))
    return out


def run_team_experiment(name: str, reps: int | None, jobs: int | None, seed: int, out: Path | None,
                        progress: bool = True, teams: tuple[int, ...] = TEAMS,
                        scenario: str | None = None) -> dict:  # fmt: skip
    """`name`: "fingerprint-together", the one experiment this runs (the registry calls every experiment by name);
    `scenario`: another floor, robot k of N on the k-th stretch of its mapping route (check_team_floor)."""
    reps = reps or 1
    if scenario is not None:
        check_team_floor(scenario, teams)
    out = Outputs(out, "fingerprint-together")
    work = [(n, "low", seed + r, scenario) for n in sorted(teams, reverse=True) for r in range(reps)]
    rows = batch_run(team_job, work, jobs=jobs, desc="fingerprint-together", progress=progress)
    rows.sort(key=lambda r: (r["robots"], r["seed"]))
    out.runs(rows)
    result = out.finish(None, _table(rows, reps, seed, scenario))
    plot(rows, out / "plot.png")
    return result


def _mean(sel: list[dict], key: str) -> float:
    values = [float(r[key]) for r in sel if r[key] != ""]
    return float(np.mean(values)) if values else math.nan


def _table(rows: list[dict], reps: int, seed: int, floor: str | None = None) -> str:
    lone = _mean([r for r in rows if r["robots"] == 1], "nodes")
    design = ("robot k surveys the k-th stretch of the corridor and its rooms" if floor is None else
              "robot k of N drives the k-th of N stretches of the floor's mapping route (the user's "
              "floor)")  # fmt: skip
    lines = [f"# Mapping together (fingerprints of places, `{floor or 'office'}`, noise low)\n",
             f"{reps} run(s) per team size (seeds {seed}..{seed + reps - 1}); {design}; robot 0's merged map is "
             "judged.\n",
             "| robots | covered after (ticks) | (s simulated) | distance per robot (m) | places known | "
             "known, never visited | nodes | a lone robot's | from others | merged into ours |",
             "|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for n in sorted({r["robots"] for r in rows}):
        sel = [r for r in rows if r["robots"] == n]
        covered = sum(r["covered_tick"] != "" for r in sel)
        lines.append(f"| {n} | {_mean(sel, 'covered_tick'):.0f} ({covered}/{len(sel)} covered) | "
                     f"{_mean(sel, 'covered_seconds'):.1f} | {_mean(sel, 'covered_distance'):.1f} | "
                     f"{_mean(sel, 'places_known'):.1f} / {sel[0]['places']} | {_mean(sel, 'known_not_visited'):.1f} | "
                     f"{_mean(sel, 'nodes'):.1f} | {lone:.1f} | {_mean(sel, 'from_others'):.1f} | "
                     f"{_mean(sel, 'merged_with_ours'):.1f} |")  # fmt: skip
    lines.append("\nThe paper maps with one robot; this is our extension (docs/fingerprint.md).")
    return "\n".join(lines) + "\n"


def plot(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ns = sorted({r["robots"] for r in rows})
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    axes[0].plot(ns, [_mean([r for r in rows if r["robots"] == n], "covered_seconds") for n in ns], "o-")
    axes[0].set(xscale="log", xticks=ns, xticklabels=ns, xlabel="robots", ylabel="s simulated",
                title="until robot 0's map covers the floor")  # fmt: skip
    axes[1].plot(ns, [_mean([r for r in rows if r["robots"] == n], "nodes") for n in ns], "o-", label="robot 0's nodes")
    axes[1].plot(ns, [_mean([r for r in rows if r["robots"] == n], "from_others") for n in ns], "s--",
                 label="of them from others")  # fmt: skip
    axes[1].set(xscale="log", xticks=ns, xticklabels=ns, xlabel="robots", title="robot 0's merged map")
    axes[1].legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
