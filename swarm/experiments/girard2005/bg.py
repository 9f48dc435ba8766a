"""The runs of `swarm experiment bg-survival | bg-choice | bg-forget | bg-fear | bg-tmaze` and of
`swarm reproduce girard2005`: the experiments of Girard et al. (2005) with the bg animat, their floors and
their maps (standalone.py runs one experiment; sections.py makes its tables).

- bg-survival (exp. 1, Table 1): condition A (taxon + topological) against B
  (taxon only) in bg-exp1, each run until death or 4 h (the paper's Table 1
  caption swaps A and B; its text is right: A uses the map).
- bg-choice (exp. 2.1, Table 2): a map built without Ep2, then Ep2 appears;
  which Ep the animat reloads at first, for W_plan 0.65 / 0.55 / 0.45; and
  the paper's control, ten tests in which Ep2 does not appear.
- bg-forget (exp. 2.2): a map built with Ep2, then Ep2 is gone; the time to
  forget it (the time to reload at Ep1 less the most direct path's).
- bg-fear (exp. 3.1, Table 3): F = 0.2 and Ep 0.1 or 0.5; Ep1 behind the
  dangerous area or the far Ep2; and the paper's control, the dangerous
  area absent (where "the animat systematically chooses the closest
  resource").
- bg-tmaze (exp. 3.2, Table 4): the T-maze with branch ratios 1, 1.5, 2;
  which branch the animat enters first.

Experiments 2 and 3 give the animat "a previously built map": a mapping run
(the animat explores without planning for at least half an hour, then until
its own map holds every kind of resource on the floor, at most
`MAPPING_SECONDS`), saved, and loaded by a test.  By default test k of every
condition loads map k, made with seed + k: the conditions are compared on
the same maps, and a table is not hostage to one mapping run (`maps=1` is
one map for every test).  Every run is the animat of
agents/controllers/bg/params.py; an experiment changes only what the paper
changes.  `--scenario FILE` runs an experiment on another floor that has the
resources it names (`FLOOR_NEEDS`).  docs/bg.md says every choice.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

from swarm.core.errors import ScenarioError
from swarm.experiments.girard2005.mapping import MAPPING_PARAMS
from swarm.experiments.runner import batch_run
from swarm.scenario import load_scenario

EXPERIMENTS = ("bg-survival", "bg-choice", "bg-forget", "bg-fear", "bg-tmaze")
SCENARIO = {"bg-survival": "bg-exp1", "bg-choice": "bg-exp2", "bg-forget": "bg-exp2", "bg-fear": "bg-exp3",
            "bg-tmaze": "tmaze", "bg-ablations": "tmaze-1", "bg-colony": "bg-colony"}  # fmt: skip
REPS = {"bg-survival": 10, "bg-choice": 15, "bg-forget": 15, "bg-fear": 20, "bg-tmaze": 15}
# What a floor's [bg] table may set: the paper's per-experiment changes (eqs. 15-20's variant, 3.1's F) and the
# colony's shared map; every other number is the declared animat's (agents/controllers/bg/params.py).
FLOOR_BG_KEYS = ("saliences", "fear", "share")
# the paper's experiments' saliences (a colony, ours, lives on any floor's)
VARIANT = {"bg-survival": "survival", "bg-choice": "survival", "bg-forget": "survival", "bg-fear": "fear",
           "bg-tmaze": "tmaze"}  # fmt: skip
MAPPING_SECONDS = MAPPING_PARAMS.seconds  # the mapping phase's budget (mapping.py declares its numbers)


# How a mapping animat maps (docs/bg.md, Experiments).  The paper gives its animat "a previously built map" and
# does not say how it was built; ours is built the way experiment 1 starts, by "random exploration and map
# building": "explore" does not plan (W_plan 0) and maps at least half an hour, so that its map covers the floor.
# "hungry" (a choice on the command line) lives as in experiment 1, planning back to the resources it found.
# Either way the mapping run ends on the animat's own state (its map holds every kind of resource on the floor)
# or after MAPPING_SECONDS, and a test is the same animat as every other run: it goes on mapping from its map.
@dataclasses.dataclass(frozen=True)
class MappingMode:
    changes: dict[str, Any]  # [bg] fields of the mapping run
    least_seconds: float  # the mapping run goes on at least this long
    text: str  # what the table's head says of it


MAPPING_MODES = {
    "hungry": MappingMode({}, 0.0, ", planning back to what it found)"),
    "explore": MappingMode(
        {"w_plan": 0.0},
        MAPPING_PARAMS.least_seconds,
        f", W_plan 0: exploring, not planning, for at least {MAPPING_PARAMS.least_seconds / 60:.0f} min)",
    ),
}
MAPPING = "explore"  # every experiment's mapping: one procedure for all
# The resources an experiment names, by name, and the walls that mark the T-maze's junction (the stem's sides):
# a floor given with --scenario must have them.
# bg-ablations runs experiments 1 and 3.2 on the one floor --scenario gives (a T-maze); bg-colony experiment 1's.
FLOOR_NEEDS = {"bg-survival": (), "bg-choice": ("Ep1", "Ep2"), "bg-forget": ("Ep1", "Ep2"),
               "bg-fear": ("Ep1", "Ep2", "DA"), "bg-tmaze": ("Ep1", "Ep2", "below_left", "below_right"),
               "bg-ablations": ("Ep1", "Ep2", "below_left", "below_right"), "bg-colony": ()}  # fmt: skip
TEST_SECONDS = 900.0  # a test of experiments 2 and 3 that has not reloaded Ep by then counts as "none"
W_PLANS = (0.65, 0.55, 0.45)
FEAR_EP = (0.1, 0.5)
RATIOS = (1.0, 1.5, 2.0)
# The paper's controls (no numbers given, only what happened): their conditions and tests.
CHOICE_CONTROL, CHOICE_CONTROL_TESTS = "no Ep2", 10
FEAR_CONTROL = {ep: f"{ep}, no DA" for ep in FEAR_EP}
WITHOUT = " without "  # a map set's name: its floor, and " without " the resources absent while mapping


def _with(s, bg: dict[str, Any] | None = None, metabolism: dict[str, Any] | None = None,
          seed: int | None = None, absent: tuple[str, ...] = (), max_ticks: int | None = None,
          sensors: dict[str, dict[str, float]] | None = None):  # fmt: skip
    """A scenario changed for one run: [bg] fields (and [bg.navigation] ones), metabolism fields, resources
    taken away, and the fields of the animats' sensors (`{"odometry": {"bias": 0.05}}`)."""
    if sensors:
        groups = tuple(dataclasses.replace(g, robot=g.robot.with_sensors(**{
            name: dataclasses.replace(getattr(g.robot.sensors, name), **fields) for name, fields in sensors.items()
        })) for g in s.groups)  # fmt: skip
        s = dataclasses.replace(s, groups=groups)
    params = dict(s.controller_params)
    params["bg"] = _merged(params.get("bg", {}), bg or {})
    obstacles = tuple(dataclasses.replace(o, appear=10**9) if o.name in absent else o for o in s.obstacles)
    m = dataclasses.replace(s.metabolism, **(metabolism or {}))
    out = dataclasses.replace(s, controller_params=params, obstacles=obstacles, metabolism=m,
                              seed=s.seed if seed is None else seed,
                              max_ticks=s.max_ticks if max_ticks is None else max_ticks)  # fmt: skip
    return out


def _merged(table: dict[str, Any], changes: dict[str, Any]) -> dict[str, Any]:
    """A [bg] table with `changes` over it; their navigation fields go into its [bg.navigation] table."""
    out = {**table, **changes}
    if "navigation" in changes:
        out["navigation"] = {**table.get("navigation", {}), **changes["navigation"]}
    return out


# ------------------------------------------------------------------ runs


def run_survival(job: tuple) -> dict:
    """One animat in bg-exp1 (or `floor`) until it dies or 4 h pass: (condition, run, seed, [bg] changes[,
    max_ticks or None[, floor[, sensor changes]]])."""
    from swarm.engines.arena import ArenaEngine

    condition, run, seed, changes, *rest = job
    cap = rest[0] if rest else None
    floor = rest[1] if len(rest) > 1 else SCENARIO["bg-survival"]
    sensors = rest[2] if len(rest) > 2 else None
    s = _with(load_scenario(floor), bg=_merged(changes, {"planning": condition == "A"}), seed=seed,
              max_ticks=cap, sensors=sensors)  # fmt: skip
    engine = ArenaEngine(s)
    act_ticks, act_ticks_moving = _run_counting_acts(engine)
    summary = engine.summary()
    r = summary["robots"][0]
    return {"condition": condition, "run": run, "seed": seed, "survival_seconds": r["survival_seconds"],
            "died": not r["alive"], "reload_e_seconds": r["reloads"]["ReloadE"] * s.control_period,
            "reload_ep_seconds": r["reloads"]["ReloadEp"] * s.control_period, "idle_acts": r["idle_acts"],
            "act_ticks": act_ticks, "act_ticks_moving": act_ticks_moving,
            "distance": r["distance"], "nodes": (r.get("map") or {}).get("nodes"),
            "wall_seconds": summary["wall_seconds"]}  # fmt: skip


MOVING = (
    0.01  # m in a control period (4 cm/s at the bg floors' 0.25 s): an animat that moved less during an act stood still
)


def _run_counting_acts(engine) -> tuple[int, int]:
    """Run the one-animat `engine` to its end; (control periods it spent in a dorsal act, those of them in
    which it moved more than MOVING).  Measured on the world's pose for the tables, not sensed by the
    animat: it says whether the loops (eq. 10) stop the animat while it eats or digests."""
    acts = moving = 0
    before = engine.world.pose[0, :2].copy()
    while not engine.done():
        engine.step(1)
        after = engine.world.pose[0, :2].copy()
        if engine.controllers[0].last.get("act", 0) > 0:
            acts += 1
            moving += math.hypot(after[0] - before[0], after[1] - before[1]) > MOVING
        before = after
    return acts, moving


def build_map(name: str, seed: int, absent: tuple[str, ...], bg: dict[str, Any] | None = None,
              mode: str = MAPPING, seconds: float = MAPPING_SECONDS,
              sensors: dict[str, dict[str, float]] | None = None) -> dict:  # fmt: skip
    """The mapping phase: the animat lives in `name` (as MAPPING_MODES[mode] says) until its own map holds every
    kind of resource on the floor (a node that learned it), or `seconds` pass; its map as plain data, with
    the resources it came within reach of (recorded, not used).  `sensors`: changes to its sensors (_with)."""
    from swarm.engines.arena import ArenaEngine

    s = load_scenario(name)
    ticks = int(seconds / s.control_period)
    p = MAPPING_PARAMS
    levels = {"energy": p.energy, "potential": p.potential, "lifetime": p.lifetime, "danger_rate": p.danger_rate}
    # mapping explores as in exp. 1 (exp. 3's saliences barely explore), and maps (a test may not)
    how = MAPPING_MODES[mode]
    bg = _merged(bg or {}, {"saliences": "survival", "learn_map": True, **how.changes})
    s = _with(s, bg=bg, metabolism={**levels, "stop_at": "death"}, seed=seed, absent=absent, max_ticks=ticks,
              sensors=sensors)  # fmt: skip
    kinds = {"ingesting": "Ep", "digesting": "E", "dangerous": "DA"}
    present = [o for o in s.obstacles if o.zone is not None and o.name not in absent]
    engine = ArenaEngine(s)
    nav, visited = engine.controllers[0].nav, set()
    wanted = {kinds[o.zone] for o in present}
    while not engine.done():
        engine.step(1)
        xy = engine.world.pose[0, :2]
        visited |= {o.name for o in present if math.hypot(xy[0] - o.centre[0], xy[1] - o.centre[1]) <= o.reach}
        if (
            engine.world.tick % 40 == 0
            and engine.world.tick * s.control_period >= how.least_seconds
            and all(len(nav.assoc[r]) and nav.assoc[r].max() > 0.5 for r in wanted)
        ):
            break  # the animat's own map holds every kind of resource the floor has
    data = engine.controllers[0].map_data()
    data["mapped_seconds"] = engine.world.tick * s.control_period
    data["visited"] = sorted(visited)
    return data


def run_test(job: tuple) -> dict:
    """One test of experiments 2 and 3 on a loaded map: (experiment, label, run, seed, scenario, bg, metabolism,
    absent, map index, map[, sensor changes])."""
    from swarm.engines.arena import ArenaEngine

    experiment, label, run, seed, name, bg, metabolism, absent, map_index, map_data, *sensors = job
    s = load_scenario(name)
    s = _with(s, bg={**bg, "map": map_data}, metabolism=metabolism, seed=seed, absent=absent,
              max_ticks=int(TEST_SECONDS / s.control_period), sensors=sensors[0] if sensors else None)  # fmt: skip
    engine = ArenaEngine(s)
    first_branch = None
    left, right, bar = junction(s) if experiment == "bg-tmaze" else (0.0, 0.0, math.inf)
    while not engine.done():
        engine.step(1)
        x = float(engine.world.pose[0, 0])
        if first_branch is None and float(engine.world.pose[0, 1]) > bar:
            first_branch = "left" if x < left else "right" if x > right else None
    r = engine.summary()["robots"][0]
    seconds = r["ingest_tick"] * s.control_period if r["ingest_tick"] is not None else None
    return {"experiment": experiment, "condition": label, "run": run, "seed": seed, "map": map_index,
            "chose": r["ingested"] or "none", "died": not r["alive"],
            "branch": first_branch or "", "seconds": seconds, "distance": r["distance"],
            "wall_seconds": engine.wall_seconds}  # fmt: skip


def junction(s) -> tuple[float, float, float]:
    """A T-maze's junction from the walls beside its stem (`below_left`, `below_right`): the animat has entered
    the left branch once north of them (y above their tops) and west of the left one's east side; the right,
    east of the right one's west side."""
    walls = {w.name: w.coords for w in s.walls}
    (_, _, x0, y0), (x1, _, _, y1) = walls["below_left"], walls["below_right"]
    return x0, x1, max(y0, y1)


def direct_seconds(name: str, stops: tuple[str, ...] = ("Ep2", "Ep1")) -> float:
    """The most direct path from the start through the reach of each of `stops` in turn (A*), at the animat's
    top speed: bg-forget's is start, Ep2, Ep1; a control's, start to Ep1."""
    from swarm.engines.goals import optimum_planner

    s = load_scenario(name)
    planner = optimum_planner(s.size, s.walls)
    res = {o.name: o for o in s.obstacles}
    here, metres = tuple(s.groups[0].starts[0][:2]), 0.0
    for k, stop in enumerate(stops):  # into each reach but the last, on from its centre
        leg = planner.plan(here, res[stop].centre)[0] - res[stop].reach
        metres += leg + (res[stop].reach if k < len(stops) - 1 else 0.0)
        here = res[stop].centre
    return metres / s.groups[0].robot.max_speed


def reps_and_maps(reps: int, maps: int | None, mapping_phase: bool = True) -> tuple[int, int]:
    """The command line's runs per condition and mapping runs (default one per test), checked: a ScenarioError
    naming the option.  Without a `mapping_phase` (bg-survival) there are no maps to choose."""
    if reps < 2:
        raise ScenarioError("command line", "--reps", "at least 2 runs per condition")
    maps = reps if maps is None else maps
    if not mapping_phase and maps != reps:
        raise ScenarioError("command line", "--maps", "bg-survival has no mapping phase (condition A maps as it lives)")
    if not 1 <= maps <= reps:
        raise ScenarioError("command line", "--maps", f"between 1 (one map for every test) and --reps ({reps})")
    return reps, maps


def check_floors(experiment: str, scenario: str | None, ratios, changes: dict[str, Any]) -> tuple[str, ...]:
    """The floors an experiment runs on (its own, or `scenario`), each checked for the resources and walls it
    names and for the [bg] changes: a ScenarioError that says what is missing."""
    from agents.controllers.bg.controller import check_table

    if scenario is not None:
        floors: tuple[str, ...] = (scenario,)
    elif experiment == "bg-tmaze":
        floors = tuple(f"tmaze-{ratio:g}" for ratio in ratios or RATIOS)
    else:
        floors = (SCENARIO[experiment],)
    for floor in floors:
        s = load_scenario(floor)
        if getattr(s, "kind", "grid") != "arena":  # a grid scenario has no kind field
            raise ScenarioError(floor, "kind", f"{experiment} runs on an arena floor")
        names = {o.name for o in s.obstacles if o.zone is not None} | {w.name for w in s.walls}
        missing = [n for n in FLOOR_NEEDS[experiment] if n not in names]
        if missing:
            example = "tmaze-1" if experiment == "bg-tmaze" else SCENARIO[experiment]
            raise ScenarioError(floor, "resources", f"{experiment} needs {', '.join(missing)} (named [[resource]] "
                                f"or [[wall]] tables, as swarm/scenarios/{example}.toml has them)")  # fmt: skip
        kinds = {o.zone for o in s.obstacles if o.zone is not None}
        if not {"ingesting", "digesting"} <= kinds:
            raise ScenarioError(floor, "resources", "the animat needs an ingesting (Ep) and a digesting (E) resource")
        _check_floor_bg(experiment, floor, s.controller_params.get("bg", {}))
        try:
            check_table(_merged(s.controller_params.get("bg", {}), changes))
        except ValueError as e:
            raise ScenarioError("command line", "--bg", str(e)) from None
    return floors


def _check_floor_bg(experiment: str, floor: str, table: dict[str, Any]) -> None:
    """A floor sets only what the paper changes per experiment, and the saliences of this experiment: a floor
    copied from another experiment's, or tuning the animat, would otherwise run another model unsaid."""
    if extra := sorted(set(table) - set(FLOOR_BG_KEYS)):
        raise ScenarioError(floor, "bg", f"{experiment} runs the declared animat: a floor's [bg] sets only "
                            f"{', '.join(FLOOR_BG_KEYS)}, not {', '.join(extra)} (a model parameter: "
                            "agents/controllers/bg/params.py; change one for a run with --bg)")  # fmt: skip
    wanted = VARIANT.get(experiment)
    if wanted is not None and table.get("saliences", "survival") != wanted:
        raise ScenarioError(floor, "bg.saliences", f"{experiment} runs the {wanted!r} saliences (the paper's for "
                            f"this experiment): set saliences = \"{wanted}\" in the floor's [bg]")  # fmt: skip


def mapped_floors(experiment: str, floors: tuple[str, ...]) -> dict[str, tuple[str, tuple[str, ...]]]:
    """The map sets an experiment needs: name -> (floor, resources absent while mapping).  Experiment 2.1 maps
    without Ep2 (it appears in the test); the control of 3.1 has its own maps, without the dangerous area."""
    if experiment == "bg-choice":
        return {f"{floors[0]}{WITHOUT}Ep2": (floors[0], ("Ep2",))}
    if experiment == "bg-fear":
        return {floors[0]: (floors[0], ()), f"{floors[0]}{WITHOUT}DA": (floors[0], ("DA",))}
    return {floor: (floor, ()) for floor in floors}


def build_map_job(job: tuple) -> dict:
    """(map set, map index, seed, floor, resources absent, [bg] changes, mapping mode[, seconds[, sensor
    changes]])."""
    name, k, seed, floor, absent, changes, mode, *rest = job
    return {"scenario": name, "index": k, "data": build_map(floor, seed, absent, changes, mode, *rest)}


def make_maps(experiment: str, count: int, seed: int, floors: tuple[str, ...], jobs: int | None, progress: bool,
          changes: dict[str, Any] | None = None, mode: str = MAPPING, seconds: float = MAPPING_SECONDS,
          sensors: dict[str, dict[str, float]] | None = None) -> dict[str, list[dict]]:  # fmt: skip
    """`count` maps per map set, map k from a mapping run with seed + k (in parallel), each at most `seconds`,
    by an animat with `sensors` changed (_with)."""
    mapped = mapped_floors(experiment, floors)
    work = [(name, k, seed + k, floor, absent, changes or {}, mode, seconds, sensors)
            for name, (floor, absent) in mapped.items() for k in range(count)]  # fmt: skip
    rows = batch_run(build_map_job, work, jobs=jobs, desc=f"{experiment} mapping", progress=progress)
    made = {(m["scenario"], m["index"]): m["data"] for m in rows}
    return {name: [made[name, k] for k in range(count)] for name in mapped}


def floor_of(map_set: str) -> str:
    """The floor a map set was made on (mapped_floors' names)."""
    return map_set.split(WITHOUT)[0]


def test_jobs(
    experiment: str, reps: int, seed: int, maps: dict[str, list[dict]], changes: dict[str, Any] | None = None
) -> list[tuple]:
    """The tests' jobs: test k of every condition loads map k mod len(maps) of its map set (paired across
    conditions).  A test's [bg]: the command line's changes, under its condition's (what the paper varies)."""
    base = dict(changes or {})
    sets = list(maps)

    def job(label, k: int, name: str, bg: dict, metabolism: dict, absent: tuple[str, ...]) -> tuple:
        m = k % len(maps[name])
        return (experiment, label, k, seed + k, floor_of(name), _merged(base, bg), metabolism, absent, m,
                maps[name][m])  # fmt: skip

    if experiment == "bg-choice":
        return [job(w, k, sets[0], {"w_plan": w, "w_taxon": 0.55}, {}, ()) for w in W_PLANS for k in range(reps)] + [
            job(CHOICE_CONTROL, k, sets[0], {"w_plan": W_PLANS[0], "w_taxon": 0.55}, {}, ("Ep2",))
            for k in range(min(reps, CHOICE_CONTROL_TESTS))
        ]
    if experiment == "bg-forget":
        return [job("Ep2 gone", k, sets[0], {}, {}, ("Ep2",)) for k in range(reps)]
    if experiment == "bg-fear":
        return [job(ep, k, sets[0], {}, {"potential": ep}, ()) for ep in FEAR_EP for k in range(reps)] + [
            job(FEAR_CONTROL[ep], k, sets[1], {}, {"potential": ep}, ("DA",)) for ep in FEAR_EP for k in range(reps)
        ]
    return [job(tmaze_label(name), k, name, {}, {}, ()) for name in maps for k in range(reps)]


def tmaze_label(floor: str) -> float | str:
    """A T-maze's condition: its branch ratio for a tmaze-R floor (bundled, or a file so named), else the floor's
    name (a file's stem)."""
    name = Path(floor).stem if floor.endswith(".toml") else floor
    tail = name.removeprefix("tmaze-")
    try:
        return float(tail) if tail != name else name
    except ValueError:
        return name
