"""The grid's side of the `swarm` command (its world kind's entry names these): its run options,
`swarm run` in one process, the summary."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from agents.controllers import CONTROLLERS
from swarm.core.errors import ScenarioError


def add_grid_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--physics", choices=["ideal", "physical"],
                   help="robot bodies: ideal = instant cell-to-cell moves, the paper's (default); physical = pymunk "
                   "discs that drive between cell centres, collide and queue")  # fmt: skip
    p.add_argument("--body-diameter", type=float, metavar="D", help="physical bodies' diameter in cells (default 0.4)")


def grid_overrides(scenario, args, common: dict):
    """The scenario with the command line's values (`common`: agents, controller, seed)."""
    if args.controller is not None and CONTROLLERS[args.controller].world != "grid":
        raise ScenarioError("command line", "controller", f"{args.controller} drives arena robots; pick an arena "
                            "scenario (zmaze, large-maze, ...) or a grid controller")  # fmt: skip
    return scenario.with_overrides(**common, physics=args.physics, body_diameter=args.body_diameter)


def grid_up_options(scenario, args) -> dict:
    """swarm_up's keywords for a grid run: the controller and the bodies the overrides chose."""
    return {"controller": scenario.controller, "physics": scenario.physics}


def run_grid(scenario, args, viewer: str | None = None) -> dict:
    """`swarm run` of a grid scenario: the compiled engine, recorded with --record; its summary."""
    from swarm.engines.grid import Engine

    engine = Engine(scenario)
    recorder = None
    if args.record:
        from swarm.recording.grid import Recorder, run_meta

        meta = run_meta(scenario, engine.world, Path(args.record).stem, args.until, "in-process")
        recorder = Recorder(args.record, engine.world, meta, viewer=viewer)
    summary = None
    try:
        summary = engine.run(args.until, args.max_iterations, progress=not args.json and sys.stderr.isatty(),
                             recorder=recorder).summary  # fmt: skip
    finally:
        if recorder is not None:
            recorder.close(summary)
    return summary


def print_grid_summary(summary: dict, as_json: bool, until: str) -> int:
    if as_json:
        print(json.dumps(summary))
    else:
        state = "finished" if summary["finished"] else f"NOT finished ({until})"
        print(
            f"{summary['scenario']}: {summary['controller']} x{summary['agents']}, seed {summary['seed']}: "
            f"{state} after {summary['iterations']} iterations\n"
            f"  delivered {summary['delivered']}/{summary['total']}, explored "
            f"{summary['explored_cells']}/{summary['reachable_cells']} cells, optimal marks "
            f"{summary['optimal_cells']}/{summary['reachable_cells']} (APF optimal: {summary['apf_optimal']})"
        )
        if "agents_lost" in summary:
            print(
                f"  {summary['ticks_per_second']} ticks/s, rejected messages {summary['rejected_messages']}, "
                f"agents joined {summary['joins']} (at most {summary.get('agents_peak')} at once), "
                f"lost {summary['agents_lost']}, missed ticks {summary['missed_ticks']}"
            )
        if summary.get("agent_processes_died"):  # swarm up: agent processes that died and the run went on
            replaced = summary.get("agent_processes_replaced")
            print(f"  agent processes died {summary['agent_processes_died']}"
                  f"{'' if replaced is None else f', replacements started {replaced}'}")  # fmt: skip
    return 0 if summary["finished"] else 1
