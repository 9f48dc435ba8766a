"""The arena's side of the `swarm` command (its world kind's entry names these): run options,
`swarm run` in one process, the summary, `swarm sense`."""

from __future__ import annotations

import argparse
import json
import math
import sys

import numpy as np

from agents.controllers.arena import ON_ERROR
from swarm.core.errors import ScenarioError


def _floats(n_min: int, n_max: int, what: str):
    def parse(text: str) -> tuple[float, ...]:
        try:
            values = tuple(float(v) for v in text.split(","))
        except ValueError:
            values = ()
        if not n_min <= len(values) <= n_max or not all(math.isfinite(v) for v in values):
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}")
        return values

    return parse


def add_arena_run_args(g) -> None:
    """The arena's run options, into their own section of --help (the entry's options_title)."""
    g.add_argument("--start", type=_floats(2, 3, "X,Y or X,Y,THETA (metres, radians)"), metavar="X,Y[,THETA]",
                   help="start pose of a one-robot run")  # fmt: skip
    g.add_argument("--goal", type=_floats(2, 2, "X,Y (metres)"), metavar="X,Y", help="goal of a one-robot run")
    g.add_argument("--noise", choices=["none", "low", "high"], help="sensor noise level (the DFT paper's)")
    g.add_argument("--max-ticks", type=int, metavar="T", help="stop after T control periods")
    g.add_argument("--threads", type=int, metavar="N",
                   help="cores for the world's sensing pass and its physics strips, 0 for every core (default: "
                        "every core for swarm run; 1 for swarm world and swarm up, whose agents share the machine); "
                        "the run is the same for every N")  # fmt: skip
    g.add_argument("--on-controller-error", choices=ON_ERROR, metavar="{idle,stop}",
                   help="a robot whose controller raises: holds still while the others go on (idle, the default), "
                        "or ends the run (stop); for the controllers in this process (swarm run) or in the agent "
                        "processes it starts (swarm up)")  # fmt: skip


def arena_overrides(scenario, args, common: dict):
    """The scenario with the command line's values (`common`: agents, controller, seed); --threads is set
    for this process's sensing pass and physics strips (it is not part of the scenario: it changes no
    bit).  `swarm run` has the machine to itself: every core unless told; a world with agent processes
    beside it keeps to one."""
    threads = getattr(args, "threads", None)
    if threads is None and getattr(args, "command", None) == "run":
        threads = 0
    if threads is not None:
        if threads < 0:
            raise ScenarioError("command line", "--threads", "0 (every core) or a number of cores")
        from world_server.arena.raycast import set_threads

        set_threads(threads)
    return scenario.with_overrides(
        **common, **{k: getattr(args, k, None) for k in ("start", "goal", "noise", "max_ticks")}
    )


def arena_up_options(scenario, args) -> dict:
    """swarm_up's keywords for an arena run: the controller asked for (None: each group's own) and
    the arena options for the world process."""
    on_error = getattr(args, "on_controller_error", None)
    return {"controller": args.controller, "world_args": arena_world_args(args),
            "agent_args": ["--on-controller-error", on_error] if on_error else []}  # fmt: skip


def arena_world_args(args) -> list[str]:
    """The arena options of `swarm up`, for its world process."""
    out = []
    for key in ("start", "goal"):
        if (value := getattr(args, key, None)) is not None:
            out += [f"--{key}", ",".join(repr(v) for v in value)]
    if getattr(args, "noise", None):
        out += ["--noise", args.noise]
    if getattr(args, "max_ticks", None):
        out += ["--max-ticks", str(args.max_ticks)]
    if getattr(args, "threads", None) is not None:
        out += ["--threads", str(args.threads)]
    return out


def run_arena(scenario, args, viewer: str | None = None) -> dict:
    """`swarm run` of an arena scenario: the engine, recorded with --record; its summary."""
    from pathlib import Path

    from swarm.engines.arena import ArenaEngine

    engine = ArenaEngine(scenario, on_error=getattr(args, "on_controller_error", None) or "idle")
    recorder = None
    if getattr(args, "record", None):
        from swarm.recording.arena import ArenaRecorder

        meta = {"run_id": Path(args.record).stem, "runtime": "in-process"}
        recorder = ArenaRecorder(args.record, engine.world, engine.goals, meta, viewer=viewer,
                                 controllers=engine.controllers)  # fmt: skip
    summary = None
    try:
        summary = engine.run(progress=not args.json and sys.stderr.isatty(), recorder=recorder)
    finally:
        if recorder is not None:
            recorder.close(summary)
    return summary


def print_arena_summary(summary: dict, as_json: bool, until: str | None = None) -> int:
    if as_json:
        print(json.dumps(summary))
    else:
        state = "finished" if summary["finished"] else "NOT finished"
        goals = f"reached {summary['reached']}/{summary['with_goal']}, " if summary["with_goal"] else ""
        print(
            f"{summary['scenario']}: {summary['controller']} x{summary['agents']}, seed {summary['seed']}, "
            f"noise {summary['noise']}: {state} after {summary['ticks']} ticks ({summary['sim_seconds']} s "
            f"simulated, {summary.get('ticks_per_second', 'n/a')} ticks/s)\n"
            f"  {goals}collisions {summary['collisions']}, "
            f"rejected actions {summary.get('rejected_actions', 'n/a')}"
        )
        for agent, why in summary.get("controller_failures", {}).items():
            print(f"  robot {agent}'s controller failed: {why}; it held still from then on")
        for r in summary["robots"][:20]:
            ratio = "n/a" if r["path_ratio"] is None else f"{r['path_ratio']:.3f}"
            lo = "n/a" if r["optimal_length"] is None else f"{r['optimal_length']:.3f}"
            first = "" if r["ticks_to_goal"] is None else f" (first at the goal at tick {r['ticks_to_goal']})"
            if r.get("goal") is None and r["optimal_length"] is None:  # no goal to reach (a wanderer, an animat)
                print(f"  robot {r['agent']} ({r['controller']}): path {r['path_length']:.3f} m, "
                      f"collisions {r['collisions']}")  # fmt: skip
            else:
                print(
                    f"  robot {r['agent']} ({r['controller']}): {'reached' if r['reached'] else 'not reached'}{first}, "
                    f"L_p {r['path_length']:.3f} m, L_o {lo} m, L_p/L_o {ratio}, collisions {r['collisions']}"
                )
            if "alive" in r:  # a metabolism (the BG paper's survival task)
                life = "alive" if r["alive"] else f"died after {r['survival_seconds']} s"
                print(f"    {life}: E {r['energy']:.3f}, Ep {r['potential']:.3f}, reloading {r['reloads']} ticks, "
                      f"first Ep at {r['ingested'] or 'none'}, acts out of reach {r['idle_acts']}")  # fmt: skip
            if r.get("map"):
                m = r["map"]
                seen = f"{m['fingerprints']} fingerprints, " if "fingerprints" in m else ""
                held = f", nodes holding {m['nodes_holding']}" if "nodes_holding" in m else ""
                others = (f"; from the others {m['from_others']} nodes, {m['merged_with_ours']} merged with ours"
                          if "from_others" in m else "")  # fmt: skip
                print(f"    map: {seen}{m['nodes']} nodes, {m['links']} links, {m['loops_closed']} loops closed"
                      f"{held}{others}")  # fmt: skip
        if len(summary["robots"]) > 20:
            print(f"  ... {len(summary['robots']) - 20} more robots (--json lists them all)")
        if "agents_lost" in summary:
            print(f"  distributed ({summary['mode']}): {summary['ticks_per_second']} ticks/s, rejected messages "
                  f"{summary['rejected_messages']}, agents joined {summary['joins']}, lost {summary['agents_lost']}, "
                  f"missed ticks {summary['missed_ticks']}")  # fmt: skip
        if summary.get("agent_processes_died"):  # swarm up: agent processes that died and the run went on
            replaced = summary.get("agent_processes_replaced")
            print(f"  agent processes died {summary['agent_processes_died']}"
                  f"{'' if replaced is None else f', replacements started {replaced}'}")  # fmt: skip
    return 0 if summary["finished"] else 1


def sense(scenario, pose: tuple[float, ...], group: int = 0) -> dict:
    """What one robot of `group` senses at `pose`, alone in the arena at tick 0."""
    from dataclasses import replace

    from world_server.arena.world import ArenaWorld

    if not 0 <= group < len(scenario.groups):
        raise ScenarioError("command line", "--group", f"expected 1 to {len(scenario.groups)}")
    g = replace(scenario.groups[group], count=1, starts=((pose[0], pose[1], pose[2] if len(pose) > 2 else 0.0),))
    world = ArenaWorld(replace(scenario, groups=(g,)))
    reading = world.perceive()[0]
    out = {"scenario": scenario.name, "robot": g.robot.name, "pose": list(world.pose[0]), "noise": scenario.noise.level}
    for k, v in reading.items():
        out[k] = np.asarray(v).tolist()
    return out


def cmd_sense(args) -> int:
    from swarm.scenario import load_scenario
    from world_server import kind_of

    scenario = load_scenario(args.scenario)
    if kind_of(scenario).name != "arena":
        raise ScenarioError(args.scenario, "kind", "swarm sense is for arena scenarios")
    if args.noise:
        scenario = scenario.with_overrides(noise=args.noise)
    result = sense(scenario, args.pose, args.group - 1)
    if args.json:
        print(json.dumps(result))
        return 0
    print(f"{result['scenario']}: {result['robot']} at x={result['pose'][0]:.4f} m, y={result['pose'][1]:.4f} m, "
          f"heading {math.degrees(result['pose'][2]):.1f} deg (noise {result['noise']})")  # fmt: skip
    for k, v in result.items():
        if k in ("scenario", "robot", "pose", "noise"):
            continue
        arr = np.asarray(v)
        text = np.array2string(arr, precision=4, max_line_width=110, threshold=80) if arr.ndim else f"{v}"
        print(f"  {k}: {text}")
    return 0


def add_sense_parser(sub) -> None:
    """`swarm sense`, a command of the arena's (its entry's commands)."""
    p = sub.add_parser("sense", help="print what a robot senses at a pose (arena scenarios)",
                       description="Place one robot of the scenario at a pose, alone, and print every reading of "
                       "its sensors at tick 0: a debugging aid, and a way to check a sensor by hand.")  # fmt: skip
    p.add_argument("scenario", metavar="SCENARIO", help="an arena scenario (TOML file or bundled name)")
    p.add_argument("--pose", required=True, type=_floats(2, 3, "X,Y[,THETA]"), metavar="X,Y[,THETA]",
                   help="where the robot stands (metres) and its heading (radians CCW from +x, default 0)")  # fmt: skip
    p.add_argument("--group", type=int, default=1, help="whose robot model (the scenario's group number, default 1)")
    p.add_argument("--noise", choices=["none", "low", "high"], help="noise level (default: the scenario's)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(handler=cmd_sense)
