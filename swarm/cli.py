"""The `swarm` command."""

from __future__ import annotations

import argparse
import json
import signal
import sys
from pathlib import Path

from agents.controllers import CONTROLLERS as CONTROLLER_REGISTRY
from swarm.cli_arena import (
    add_arena_run_args,
    add_sense_parser,
    arena_overrides,
    arena_world_args,
    cmd_sense,
    print_arena_summary,
    run_arena,
)
from swarm.core.errors import RecordingError, RunError, ScenarioError, raise_interrupt
from swarm.scenario import PRESET_HELP, bundled_scenarios, is_arena, load_scenario

CONTROLLERS = CONTROLLER_REGISTRY.names()
FINGERPRINT_EXPERIMENTS = ("fingerprint-calibrate", "fingerprint-map", "fingerprint-localize", "fingerprint-together")
DFT_EXPERIMENTS = ("dft-case1", "dft-case2", "dft-case3", "dft-together")
BG_EXPERIMENTS = ("bg-survival", "bg-choice", "bg-forget", "bg-fear", "bg-tmaze", "bg-colony")

DESCRIPTION = """\
swarm: multi-robot foraging with c-marking agents (Simonin et al. 2007),
the plain marking agents and the pheromone ant baseline, on a grid; and the
arena, a continuous world of walls and differential-drive robots.

examples:
  swarm up setup1 --agents 20 --seed 1          # world + 20 agent processes over zenoh, recorded
  swarm report runs/<run-id>.rrd                # summary and plots from the recording
  swarm replay runs/<run-id>.rrd --web          # scrub through it in the rerun web viewer
  swarm run setup1 --agents 20 --seed 3         # the same swarm in one process (fast)
  swarm run maze --physics physical --record maze.rrd
  swarm run maze --controller marking --until converged --json
  swarm experiment table1 --reps 100
  swarm run zmaze --noise high                  # an arena: the carrot e-puck in the DFT paper's Z-maze
  swarm sense zmaze --pose 0.2,0.5,0            # what a robot senses there
  swarm run office --controller fingerprint     # the scout maps the office floor with fingerprints of places
  swarm experiment fingerprint-localize         # map on one tour, localize on another (Tapus et al. 2006)
  swarm run zmaze --controller dft              # plan and act with dynamic neural fields (Billing et al. 2015)
  swarm experiment dft-case1                    # SPA beside follow the carrot on the paper's 100 pairs
  swarm run bg-exp1                             # the basal-ganglia animat survives (Girard et al. 2005)
  swarm up bg-colony                            # four animats, each its own process, sharing one map
  swarm bench engine | distributed | recording | arena | fingerprint | dft | bg
  docker compose up swarm                       # the same in containers (compose.yaml, docs/docker.md)
"""


def _positive(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text}")
    return value


def _ratios(text: str) -> tuple[float, ...]:
    from swarm.experiments.girard2005.bg import RATIOS

    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if not values or any(v not in RATIOS for v in values):
        raise argparse.ArgumentTypeError(f"expected some of {','.join(f'{r:g}' for r in RATIOS)} (the tmaze-R "
                                         f"scenarios), got {text}")  # fmt: skip
    return values


def _bg_setting(text: str) -> tuple[str, object]:
    """KEY=VALUE, the value a TOML literal (0.5, true, "fear"); navigation.KEY names a [bg.navigation] field."""
    import tomllib

    key, sep, value = text.partition("=")
    try:
        parsed = tomllib.loads(f"v = {value}")["v"] if sep and key else None
    except tomllib.TOMLDecodeError:
        parsed = None
    if parsed is None or isinstance(parsed, (dict, list)):
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE (e.g. usable_threshold=0.5, navigation.anchor=0.2), "
                                         f"got {text}")  # fmt: skip
    return key.strip(), parsed


def _bg_table(settings: list[tuple[str, object]] | None) -> dict:
    """--bg settings as a [bg] table (navigation.KEY into its [bg.navigation] table)."""
    table: dict = {}
    for key, value in settings or ():
        if key.startswith("navigation."):
            table.setdefault("navigation", {})[key.removeprefix("navigation.")] = value
        else:
            table[key] = value
    return table


def _sizes(text: str) -> tuple[int, ...]:
    from swarm.experiments.girard2005.colony import NEST

    try:
        values = tuple(int(v) for v in text.split(","))
    except ValueError:
        values = ()
    if not values or any(not 1 <= v <= len(NEST) for v in values):
        raise argparse.ArgumentTypeError(f"expected colony sizes from 1 to {len(NEST)} (the nest's places), "
                                         f"got {text}")  # fmt: skip
    return values


def _seed(text: str) -> int:
    value = int(text)
    if not 0 <= value < 2**63:
        raise argparse.ArgumentTypeError(f"expected a seed from 0 to 2**63-1, got {text}")
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="swarm", description=DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    run = sub.add_parser(
        "run",
        help="run a scenario to completion in one process",
        description="Run a scenario in the in-process engine and print its summary.",
    )
    run.add_argument(
        "scenario",
        metavar="SCENARIO",
        help=f"a TOML file, a preset ({PRESET_HELP}) or a bundled name ({', '.join(bundled_scenarios())})",
    )
    run.add_argument("--agents", type=_positive, help="number of agents (default: the scenario's)")
    run.add_argument("--controller", choices=CONTROLLERS, help="controller to run")
    run.add_argument("--seed", type=_seed, help="seed of the map and of every random choice")
    _physics_args(run)
    add_arena_run_args(run)
    _record_args(run, "write a rerun recording of the run to FILE (.rrd)")
    run.add_argument(
        "--until",
        choices=["foraged", "converged", "both"],
        default="foraged",
        help="foraged: every unit delivered (default); converged: marks equal the BFS "
        "distance on every reachable cell; both",
    )
    run.add_argument("--max-iterations", type=_positive, default=1_000_000, metavar="M",
                     help="stop after M iterations if not done (default 1000000)")  # fmt: skip
    run.add_argument("--json", action="store_true", help="print one JSON object instead of text")

    exp = sub.add_parser(
        "experiment",
        help="reproduce a table of the paper",
        description="Rerun one of the paper's experiments (or the congestion study, which adds robot bodies "
        "to Table 1) and write runs.csv, summary.csv, table.md (paper beside ours) and plot.png.",
    )
    from swarm.experiments.simonin2007.tables import EXPERIMENTS

    names_help = "; ".join(f"{e.name}: {e.title.split(': ', 1)[1]}" for e in EXPERIMENTS.values())
    names_help += "; carrot: follow the carrot in zmaze and large-maze at three noise levels (DFT paper, cases 1-2)"
    names_help += (
        "; fingerprint-calibrate | fingerprint-map | fingerprint-localize: topological mapping and "
        "localization with fingerprints of places on office (Tapus et al. 2006)"
    )
    names_help += (
        "; dft-case1 | dft-case2 | dft-case3: the dft controller (Billing et al. 2015) in zmaze and large-maze "
        "beside follow the carrot, and replanning round an obstacle; dft-together: a scout shares the obstacle "
        "it meets over the context key space"
    )
    names_help += (
        "; bg-survival | bg-choice | bg-forget | bg-fear | bg-tmaze: the basal-ganglia animat (Girard et al. "
        "2005): survival with and without its map, a new resource, a removed one, fear against need, the T-maze; "
        "bg-colony: survival against colony size, with and without a shared map"
    )
    exp.add_argument("name", choices=[*EXPERIMENTS, "carrot", *FINGERPRINT_EXPERIMENTS, *DFT_EXPERIMENTS,
                                      *BG_EXPERIMENTS],
                     metavar="NAME",
                     help=names_help)  # fmt: skip
    exp.add_argument(
        "--scenario",
        help="carrot: zmaze or large-maze (default both); fingerprint-*: a floor with "
        "'mapping', 'localize' and 'localize-off-map' routes and place zones (default office)",
    )
    exp.add_argument("--reps", type=_positive, help="runs per configuration (default per experiment)")
    exp.add_argument("--noise", choices=["none", "low", "high"], help="dft-*: only the conditions at this noise level")
    exp.add_argument(
        "--max-steps",
        type=_positive,
        metavar="T",
        help="dft-*: run length limit in steps of 64 ms (default 3000, the paper's; the code used 2000)",
    )
    exp.add_argument(
        "--ratios",
        type=_ratios,
        metavar="R,R,...",
        help="bg-tmaze: right / left branch length ratios to run (default 1,1.5,2: tmaze-R scenarios)",
    )
    exp.add_argument(
        "--maps",
        type=_positive,
        metavar="N",
        help="bg-choice | bg-forget | bg-fear | bg-tmaze: mapping runs per scenario; test k loads map "
        "k mod N (default: one per test; 1: one map for every test)",
    )
    exp.add_argument(
        "--mapping",
        choices=["hungry", "explore"],
        help="bg-choice | bg-forget | bg-fear | bg-tmaze: how the mapping animat maps: hungry, planning back to "
        "what it found, or exploring without planning for at least 30 min (default: explore for bg-fear, "
        "hungry for the others; docs/bg.md)",
    )
    exp.add_argument(
        "--bg",
        type=_bg_setting,
        action="append",
        metavar="KEY=VALUE",
        help="bg-*: change a [bg] setting in every run, mapping runs included (repeatable; e.g. "
        "usable_threshold=0.5, navigation.pursuit=0.5: docs/bg.md)",
    )
    exp.add_argument("--sizes", type=_sizes, metavar="N,N,...", help="bg-colony: colony sizes to run (default 1,2,4,8)")
    exp.add_argument("--jobs", type=_positive, help="worker processes (default: all cores)")
    exp.add_argument("--seed", type=_seed, default=0, help="first seed (runs use seed..seed+reps-1)")
    exp.add_argument("--out", type=Path, help="output folder (default results/NAME)")

    bench = sub.add_parser("bench", help="measure throughput", description="Measure throughput.")
    bench.add_argument("target", choices=["engine", "distributed", "recording", "arena", "fingerprint", "dft",
                                          "bg"],
                       help="engine: the in-process engine; distributed: world + agent processes; "
                       "recording: what recording costs; arena: sensing and physics of the arena; "
                       "fingerprint: features, one alignment, localization against 20-1000 nodes; "
                       "dft: one step of the neural-field architecture at 100x100 and 210x210 cells; "
                       "bg: the animat's GPR loops, sensing, navigation and step, as real-time factors")  # fmt: skip
    bench.add_argument("--json", action="store_true", help="print one JSON object")
    bench.add_argument("--quick", action="store_true", help="shorter measurement")
    bench.add_argument("--pairs", type=_positive, default=3,
                       help="distributed: floor/run pairs measured in turn per size; the share is their median "
                       "(default 3)")  # fmt: skip

    world = sub.add_parser(
        "world",
        help="serve a scenario's world over zenoh (the world process)",
        description="Host (or join) a zenoh router and run the world in lock-step for agent processes.",
    )
    _scenario_args(world)
    world.add_argument("--run-id", default="default", help="key space swarm/<run-id>/... (default: default)")
    where = world.add_mutually_exclusive_group()
    where.add_argument("--listen", default="tcp/127.0.0.1:7447", metavar="ENDPOINT",
                       help="host a router listening here (default tcp/127.0.0.1:7447)")  # fmt: skip
    where.add_argument("--connect", metavar="ENDPOINT", help="join an existing router instead")
    _tick_args(world)
    world.add_argument("--start-with", type=_positive, metavar="K",
                       help="start ticking once K agents have joined (default: --agents); more may join later, "
                       "up to --agents")  # fmt: skip
    world.add_argument("--max-misses", type=_positive, default=3, metavar="K",
                       help="an agent that misses K ticks in a row is lost (default 3)")  # fmt: skip
    world.add_argument("--summary-file", metavar="FILE", help="also write the summary JSON here")
    world.add_argument("--quiet", action="store_true", help="no log lines on stderr (swarm up shows its own progress)")
    world.add_argument("--null", action="store_true", help=argparse.SUPPRESS)  # benchmark floor
    world.add_argument(
        "--state-dir",
        default="runs",
        metavar="DIR",
        help="persist the world to DIR/<run-id>.state.npz (an arena: .arena.npz) and resume from it on "
        "restart (default runs)",
    )
    world.add_argument("--persist-every", type=int, default=50, metavar="K",
                       help="persist every K ticks (default 50; 0: only at the end; an arena saves at its "
                       "physics checkpoints, every lcm(K, checkpoint) ticks)")  # fmt: skip
    world.add_argument("--start-timeout", type=float, default=600.0, metavar="S",
                       help="give up if the agents have not all joined after S seconds (default 600)")  # fmt: skip
    world.add_argument("--linger", type=float, default=0.0, metavar="S",
                       help="keep serving swarm/<run-id>/marks/** for S seconds after the run")  # fmt: skip
    _record_args(world, "write a rerun recording of the run to FILE (.rrd), or into FOLDER/ as <run-id>-<UTC time>.rrd")

    agent = sub.add_parser(
        "agent",
        help="run agent process(es) that join a world",
        description="Join a world over zenoh and run one controller (or K with --count).",
    )
    agent.add_argument("--controller", choices=CONTROLLERS, default="cmarking")
    _client_args(agent)
    agent.add_argument("--count", type=_positive, default=1, metavar="K", help="independent agents in this process")
    agent.add_argument("--null", action="store_true", help=argparse.SUPPRESS)  # benchmark floor
    agent.add_argument("--join-timeout", type=float, default=60.0, metavar="S",
                       help="give up when no world has answered within S seconds (default 60)")  # fmt: skip

    up = sub.add_parser(
        "up",
        help="launch a world and N agent processes, and follow the run",
        description="Start the world (with its embedded router) and N agent processes as separate OS "
        "processes, show progress, and print the run summary.",
    )
    _scenario_args(up)
    _tick_args(up)
    up.add_argument("--run-id", help="key space swarm/<run-id>/... (default: a fresh id)")
    up.add_argument("--listen", default="tcp/127.0.0.1:7447", metavar="ENDPOINT", help="the router's endpoint")
    _record_args(up, "where the recording goes (default runs/<run-id>.rrd)")
    up.add_argument("--no-record", action="store_true", help="do not record the run")

    replay = sub.add_parser(
        "replay",
        help="open a recording in the rerun viewer",
        description="Open a recording in the native rerun viewer, or serve the web viewer (--web) and print "
        "the URL to open.",
    )
    replay.add_argument("file", metavar="FILE", help="a .rrd written by swarm up or swarm run --record")
    replay.add_argument("--web", action="store_true", help="serve the web viewer instead of opening a window")
    replay.add_argument("--port", type=int, default=9090, help="web viewer HTTP port (default 9090)")
    replay.add_argument("--grpc-port", type=int, default=9876, help="port of the data stream (default 9876)")
    replay.add_argument("--bind", default="127.0.0.1", help="address to serve on (0.0.0.0 for other machines)")

    rep = sub.add_parser(
        "report",
        help="summary and plots from a recording",
        description="Read a recording back and print the run summary; write plots (delivered, share of "
        "optimal cells, agents per state vs tick) and summary.json.",
    )
    rep.add_argument("file", metavar="FILE", help="a .rrd written by swarm up or swarm run --record")
    rep.add_argument("--out", metavar="DIR", help="where the plots go (default: FILE without .rrd)")
    rep.add_argument("--json", action="store_true", help="print one JSON object instead of text")

    mon = sub.add_parser(
        "monitor",
        help="follow a running world and print its summary when the run ends",
        description="Follow a world's run over zenoh (progress bar on a terminal, else a log line every few "
        "seconds), print the run summary when the world says it has ended, and exit 0 if the run finished "
        "(1 if it stopped unfinished).  `docker compose up swarm` runs this.",
    )
    _client_args(mon)
    mon.add_argument("--log-every", type=float, default=5.0, metavar="S", help="seconds between log lines")
    mon.add_argument("--start-timeout", type=float, default=600.0, metavar="S",
                     help="give up if no world answers for S seconds (default 600)")  # fmt: skip
    mon.add_argument("--json", action="store_true", help="print one JSON object instead of text")

    st = sub.add_parser(
        "status",
        help="ask a router or a world whether it is up (health checks)",
        description="Exit 0 and print the run's state if the world of --run-id answers (with --router: if "
        "the router accepts a session); exit 1 if not.",
    )
    _client_args(st)
    st.add_argument("--router", action="store_true", help="only check that the router answers")
    st.add_argument("--timeout", type=float, default=3.0, metavar="S", help="how long to wait (default 3)")
    st.add_argument("--json", action="store_true", help="print one JSON object")

    router = sub.add_parser(
        "router",
        help="run a bare zenoh router (for worlds and agents on several hosts)",
        description="Run a zenoh router that worlds (--connect), agents and monitors join; multicast "
        "scouting stays off, so every process names the router's endpoint.",
    )
    router.add_argument("--listen", default="tcp/0.0.0.0:7447", metavar="ENDPOINT",
                        help="where to listen (default tcp/0.0.0.0:7447)")  # fmt: skip

    prep = sub.add_parser(
        "prepare",
        help="compile the kernels and the agents' step now, so runs start at once",
        description="Compile (once per source version, ~1-2 minutes on 2 cores) the engine, world and "
        "controller kernels and the agents' ahead-of-time step into ~/.cache/swarm (or $XDG_CACHE_HOME). "
        "swarm up does it by itself; container images do it at build time.",
    )
    prep.add_argument("--require-aot", action="store_true",
                      help="fail if the ahead-of-time build cannot be made (no C compiler)")  # fmt: skip

    add_sense_parser(sub)
    sub.add_parser("scenarios", help="list presets and bundled scenarios")
    return parser


def _client_args(p: argparse.ArgumentParser) -> None:
    """Where a client of a running world finds it: agents, monitor, status."""
    p.add_argument("--connect", default="tcp/127.0.0.1:7447", metavar="ENDPOINT", help="the router")
    p.add_argument("--run-id", default="default", help="the world's run id (default: default)")


def _tick_args(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--mode",
        choices=["lockstep", "realtime"],
        default="lockstep",
        help="lockstep: barrier per tick (equals swarm run); realtime: fixed rate, latest action wins",
    )
    p.add_argument("--rate", type=float, default=20.0, metavar="HZ", help="ticks per second in realtime mode")
    p.add_argument("--deadline", type=float, default=2.0, metavar="S", help="lock-step: per-tick deadline in seconds")


def _record_args(p: argparse.ArgumentParser, record_help: str) -> None:
    p.add_argument("--record", metavar="FILE", help=record_help)
    p.add_argument("--viewer", nargs="?", const="spawn", metavar="URL",
                   help="also stream to a live rerun viewer: spawn one here, or give its gRPC URL "
                   "(rerun+http://HOST:9876/proxy)")  # fmt: skip


def _viewer_url(viewer: str | None) -> str | None:
    """`--viewer` alone spawns a native viewer here and streams to it."""
    if viewer != "spawn":
        return viewer
    import rerun as rr

    try:
        rr.spawn(port=9876, connect=False)
    except Exception as exc:  # no binary, no display: say so, keep recording to the file
        print(f"swarm: could not start a rerun viewer here ({exc}); recording to the file only", file=sys.stderr)
        return None
    return "rerun+http://127.0.0.1:9876/proxy"


def _physics_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--physics", choices=["ideal", "physical"],
                   help="robot bodies: ideal = instant cell-to-cell moves, the paper's (default); physical = pymunk "
                   "discs that drive between cell centres, collide and queue")  # fmt: skip
    p.add_argument("--body-diameter", type=float, metavar="D", help="physical bodies' diameter in cells (default 0.4)")


def _scenario_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("scenario", metavar="SCENARIO", help=f"a TOML file, a preset ({PRESET_HELP}) or a bundled name")
    p.add_argument("--agents", type=_positive, help="number of agents (default: the scenario's)")
    p.add_argument("--controller", choices=CONTROLLERS, help="controller to run")
    p.add_argument("--seed", type=_seed, help="seed of the map and of every random choice")
    _physics_args(p)
    p.add_argument("--until", choices=["foraged", "converged", "both"], default="foraged", help="when the run ends")
    p.add_argument("--max-iterations", type=_positive, default=1_000_000, metavar="M", help="stop after M ticks")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of text")
    add_arena_run_args(p)


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    signal.signal(signal.SIGTERM, raise_interrupt)
    try:
        return COMMANDS[args.command](args)
    except (ScenarioError, RecordingError) as exc:
        print(f"swarm: error: {exc}", file=sys.stderr)
        return 2
    except (ConnectionError, TimeoutError, RunError) as exc:
        print(f"swarm: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("swarm: interrupted", file=sys.stderr)
        return 130


def _print_summary(summary: dict, as_json: bool, until: str) -> int:
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
    return 0 if summary["finished"] else 1


def _scenario(args):
    scenario = load_scenario(args.scenario)
    common = {"agents": args.agents, "controller": args.controller, "seed": args.seed}
    if is_arena(scenario):
        return scenario.with_overrides(**common, **arena_overrides(args))
    if args.controller is not None and CONTROLLER_REGISTRY[args.controller].world == "arena":
        raise ScenarioError("command line", "controller", f"{args.controller} drives arena robots; pick an arena "
                            "scenario (zmaze, large-maze, ...) or a grid controller")  # fmt: skip
    return scenario.with_overrides(**common, physics=args.physics, body_diameter=args.body_diameter)


def cmd_world(args) -> int:
    from swarm.world_process import serve

    scenario = _scenario(args)
    if args.until != "foraged" and scenario.controller == "ant":
        raise ScenarioError("command line", "until", "ants build no marks; only --until foraged applies to them")
    summary = serve(scenario, args.run_id, args.summary_file, quiet=args.quiet,
                    listen=None if args.connect else args.listen,
                    connect=args.connect, deadline=args.deadline, max_misses=args.max_misses, until=args.until,
                    start_with=args.start_with,
                    max_iterations=args.max_iterations, linger=args.linger,
                    start_timeout=args.start_timeout, null=args.null,
                    state_dir=args.state_dir, persist_every=args.persist_every, mode=args.mode,
                    rate=args.rate, record=args.record, viewer=_viewer_url(args.viewer))  # fmt: skip
    return _print_any(summary, args.json, args.until)


def cmd_agent(args) -> int:
    from agents.runtime import JoinRefused
    from agents.runtimes import make_runtime
    from swarm.core.wire import ENDED

    try:
        runtime = make_runtime(args.run_id, args.controller, args.connect, args.count, null=args.null,
                               join_timeout=args.join_timeout)  # fmt: skip
    except JoinRefused as exc:
        print(f"swarm: {exc}", file=sys.stderr)
        return 0 if ENDED in str(exc) else 2  # a late agent of a finished run has nothing to do
    try:
        runtime.run()
    finally:
        runtime.close()
    return 0


def cmd_up(args) -> int:
    from swarm.launcher import swarm_up
    from world_server.server import new_run_id

    scenario = _scenario(args)
    if args.until != "foraged" and scenario.controller == "ant":
        raise ScenarioError("command line", "until", "ants build no marks; only --until foraged applies to them")
    run_id = args.run_id or new_run_id()
    record = None if args.no_record else (args.record or f"runs/{run_id}.rrd")
    arena = is_arena(scenario)
    summary = swarm_up(args.scenario, scenario.agents, args.controller if arena else scenario.controller, args.seed,
                       run_id, args.listen, args.until, args.max_iterations, args.deadline,
                       progress=not args.json and sys.stderr.isatty(), mode=args.mode, rate=args.rate,
                       physics=None if arena else scenario.physics, record=record, viewer=args.viewer,
                       world_args=arena_world_args(args))  # fmt: skip
    if summary.get("recording"):
        _point_at_recording(summary["recording"])
    return _print_any(summary, args.json, args.until)


def _print_any(summary: dict, as_json: bool, until: str) -> int:
    if summary.get("kind") == "arena":
        return print_arena_summary(summary, as_json)
    return _print_summary(summary, as_json, until)


def cmd_run(args) -> int:
    from swarm.engines.grid import Engine

    scenario = _scenario(args)
    if is_arena(scenario):
        return run_arena(args, scenario, _viewer_url(args.viewer) if args.record else None)
    engine = Engine(scenario)
    recorder = None
    if args.record:
        from swarm.recording.grid import Recorder, run_meta

        meta = run_meta(scenario, engine.world, Path(args.record).stem, args.until, "in-process")
        recorder = Recorder(args.record, engine.world, meta, viewer=_viewer_url(args.viewer))
    summary = None
    try:
        summary = engine.run(args.until, args.max_iterations, progress=not args.json and sys.stderr.isatty(),
                             recorder=recorder).summary  # fmt: skip
    finally:
        if recorder is not None:
            recorder.close(summary)
    if recorder is not None:
        _point_at_recording(args.record)
    return _print_summary(summary, args.json, args.until)


def _point_at_recording(path: str) -> None:
    print(f"recording: {path}\n  open it:           swarm replay {path}   (or --web)\n"
          f"  summary and plots: swarm report {path}", file=sys.stderr)  # fmt: skip


def cmd_replay(args) -> int:
    from swarm.review.report import replay

    return replay(args.file, web=args.web, web_port=args.port, grpc_port=args.grpc_port, bind=args.bind)


def cmd_report(args) -> int:
    from swarm.review.report import report

    result = report(args.file, args.out)
    if args.json:
        print(json.dumps(result["summary"]))
    else:
        summary = result["summary"]
        _print_any(summary, False, summary.get("until", "foraged"))
        if "rejected_messages" in summary:
            print(f"  {summary['mode']}: tick latency p50 {summary['tick_ms_p50']} ms, "
                  f"p99 {summary['tick_ms_p99']} ms, rejected messages {summary['rejected_messages']}")  # fmt: skip
        print(f"wrote {', '.join(result['plots'])} and {result['out']}/summary.json")
    return 0


def cmd_experiment(args) -> int:
    if args.bg and args.name not in BG_EXPERIMENTS[:-1]:
        raise ScenarioError("command line", "--bg", "this is for the bg-* experiments but bg-colony")
    if args.name == "fingerprint-together":
        if args.scenario:
            raise ScenarioError("command line", "--scenario", "fingerprint-together surveys office")
        from swarm.experiments.tapus2006.team import run_team_experiment

        result = run_team_experiment(args.reps, args.jobs, args.seed, args.out)
        print(result["markdown"])
        print(f"wrote {result['out']}/runs.csv, table.md, plot.png")
        return 0
    if args.name in FINGERPRINT_EXPERIMENTS:
        from swarm.experiments.tapus2006.fingerprint import run_fingerprint_experiment

        result = run_fingerprint_experiment(args.name, args.scenario, args.reps, args.jobs, args.seed, args.out)
        print(result["markdown"])
        print(f"wrote {result['out']}/runs.csv, table.md" + ("" if args.name.endswith("calibrate") else
                                                             ", summary.csv, plot.png"))  # fmt: skip
        return 0
    if args.name in DFT_EXPERIMENTS:
        from swarm.experiments.billing2015.dft import run_dft_experiment

        result = run_dft_experiment(args.name, args.scenario, args.reps, args.jobs, args.seed, args.out,
                                    noise=args.noise, max_ticks=args.max_steps)  # fmt: skip
        print(result["markdown"])
        extra = ", paths.png, paths.npz" if args.name == "dft-case3" else ""
        print(f"wrote {result['out']}/runs.csv, summary.csv, table.md, plot.png{extra}")
        return 0
    if args.noise or args.max_steps:
        raise ScenarioError("command line", "--noise/--max-steps", "these are for the dft-* experiments")
    if args.name == "bg-colony":
        if args.scenario or args.ratios or args.maps or args.mapping:
            raise ScenarioError("command line", "--scenario/--ratios/--maps/--mapping",
                                "bg-colony runs bg-colony, with no mapping phase; give --sizes")  # fmt: skip
        from swarm.experiments.girard2005.colony import run_colony_experiment

        result = run_colony_experiment(args.sizes, args.reps, args.jobs, args.seed, args.out)
        print(result["markdown"])
        print(f"wrote {result['out']}/runs.csv, summary.csv, table.md, plot.png")
        return 0
    if args.sizes:
        raise ScenarioError("command line", "--sizes", "this is for bg-colony")
    if args.name in BG_EXPERIMENTS:
        from swarm.experiments.girard2005.bg import run_bg_experiment

        result = run_bg_experiment(args.name, args.scenario, args.reps, args.jobs, args.seed, args.out,
                                   ratios=args.ratios, maps=args.maps, bg=_bg_table(args.bg),
                                   mapping=args.mapping)  # fmt: skip
        print(result["markdown"])
        print(f"wrote {result['out']}/runs.csv, summary.csv, table.md, plot.png")
        return 0
    if args.ratios:
        raise ScenarioError("command line", "--ratios", "this is for bg-tmaze")
    if args.maps or args.mapping:
        raise ScenarioError("command line", "--maps/--mapping",
                            "these are for bg-choice, bg-forget, bg-fear and bg-tmaze")  # fmt: skip
    if args.name == "carrot":
        from swarm.experiments.billing2015.carrot import run_carrot_experiment

        result = run_carrot_experiment(args.scenario, args.reps, args.jobs, args.seed, args.out)
        print(result["markdown"])
        print(f"wrote {result['out']}/runs.csv, summary.csv, table.md, plot.png")
        return 0
    if args.scenario:
        raise ScenarioError(
            "command line", "--scenario", f"{args.name} uses the paper's setups; --scenario is for carrot"
        )
    from swarm.experiments.simonin2007.tables import run_experiment

    result = run_experiment(args.name, args.reps, args.jobs, args.seed, args.out)
    print(result["markdown"])
    print(f"wrote {result['out']}/runs.csv, summary.csv, table.md, plot.png")
    return 0


def cmd_bench(args) -> int:
    if args.target == "bg":
        from swarm.bench.bg import bench_bg, format_bg_bench

        result = bench_bg(quick=args.quick)
        print(json.dumps(result) if args.json else format_bg_bench(result))
        return 0
    if args.target == "dft":
        from swarm.bench.dft import bench_dft, format_dft_bench

        result = bench_dft(quick=args.quick)
        print(json.dumps(result) if args.json else format_dft_bench(result))
        return 0
    if args.target == "fingerprint":
        from swarm.bench.fingerprint import bench_fingerprint, format_fingerprint_bench

        result = bench_fingerprint(quick=args.quick)
        print(json.dumps(result) if args.json else format_fingerprint_bench(result))
        return 0
    if args.target == "arena":
        from swarm.bench.arena import bench_arena, format_arena_bench

        result = bench_arena(quick=args.quick)
        print(json.dumps(result) if args.json else format_arena_bench(result))
        return 0
    if args.target == "recording":
        from swarm.bench.recording import bench_recording, format_recording_bench

        result = bench_recording(quick=args.quick)
        print(json.dumps(result) if args.json else format_recording_bench(result))
        return 0
    if args.target == "distributed":
        from swarm.bench.distributed import bench_distributed, format_distributed_bench

        result = bench_distributed(sizes=(10, 50) if args.quick else (10, 50, 100, 200),
                                   packed=200 if args.quick else 1000, pairs=args.pairs)  # fmt: skip
        print(json.dumps(result) if args.json else format_distributed_bench(result))
        return 0
    from swarm.bench.engine import bench_engine, format_engine_bench

    result = bench_engine(quick=args.quick)
    print(json.dumps(result) if args.json else format_engine_bench(result))
    return 0


def cmd_monitor(args) -> int:
    from swarm.monitor import monitor

    summary = monitor(args.connect, args.run_id, progress=not args.json and sys.stderr.isatty(),
                      log_every=args.log_every, start_timeout=args.start_timeout)  # fmt: skip
    return _print_any(summary, args.json, summary.get("until", "foraged"))


def cmd_status(args) -> int:
    from swarm.monitor import status

    info = status(args.connect, args.run_id, router_only=args.router, timeout=args.timeout)
    if info is None:
        what = f"router at {args.connect}" if args.router else f"world of run {args.run_id!r} via {args.connect}"
        print(f"swarm: no {what} answered", file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps({k: v for k, v in info.items() if k != "members"}))
    elif args.router:
        print(f"router at {args.connect}: up")
    else:
        state = "ended" if info.get("ended") else "running"
        done = (f"reached {info['reached']}/{info['with_goal']}" if info.get("kind") == "arena"
                else f"delivered {info['delivered']}/{info['total']}")  # fmt: skip
        print(f"run {args.run_id}: {state} at tick {info['iterations']}, {done}, {info['agents_alive']} agents alive")
    return 0


def cmd_router(args) -> int:
    from swarm.monitor import serve_router

    serve_router(args.listen)
    return 0


def cmd_prepare(args) -> int:
    from swarm.launcher import prepare

    aot_built = prepare(progress=True, engine=True, arena=True)
    print(f"swarm: kernels compiled; agents' ahead-of-time step: {'built' if aot_built else 'MISSING (JIT fallback)'}")
    return 0 if aot_built or not args.require_aot else 1


def cmd_scenarios(args) -> int:
    print(f"presets: {PRESET_HELP}")
    print(f"bundled: {', '.join(bundled_scenarios())}  (in {Path(__file__).parent / 'scenarios'})")
    return 0


COMMANDS = {"run": cmd_run, "experiment": cmd_experiment, "bench": cmd_bench, "scenarios": cmd_scenarios,
            "world": cmd_world, "agent": cmd_agent, "up": cmd_up, "replay": cmd_replay,
            "report": cmd_report, "monitor": cmd_monitor, "status": cmd_status, "router": cmd_router,
            "prepare": cmd_prepare, "sense": cmd_sense}  # fmt: skip


if __name__ == "__main__":
    sys.exit(main())
