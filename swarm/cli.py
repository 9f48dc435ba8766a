"""The `swarm` command."""

from __future__ import annotations

import argparse
import json
import signal
import sys
from pathlib import Path

from agents.controllers import CONTROLLERS as CONTROLLER_REGISTRY
from swarm.cli_check import add_check_parsers
from swarm.cli_reproduce import add_reproduce_parser, cmd_reproduce
from swarm.cli_secure import add_credentials_parser, agent_identity, credentials_arg, identity, up_args
from swarm.cli_sweep import add_sweep_parser
from swarm.core.errors import RecordingError, RunError, ScenarioError, StateError, raise_interrupt
from swarm.core.registry import Option, Registry, resolve
from swarm.core.tables import positive, seed
from swarm.experiments.executors import add_executor_options, executor_for, use
from swarm.scenario import PRESET_HELP, bundled_scenarios, load_scenario
from world_server import WORLD_KINDS, kind_of
from world_server.grid.scenario import DEFAULT_CONTROLLER

CONTROLLERS = CONTROLLER_REGISTRY.names()
CONTROLLER_HELP = f"controller to run: {', '.join(CONTROLLERS)}, or your own as module:Class"


def controller_name(text: str) -> str:
    """--controller: a registered name, or a user's class as module:Class (loaded now, so that a
    bad one is one line before anything starts)."""
    try:
        CONTROLLER_REGISTRY[text]
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


DESCRIPTION_TEMPLATE = """\
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
  swarm sweep my-sweep.toml --jobs 4            # scenarios x a parameter grid x seeds: runs.csv, summary, plots
  swarm run zmaze --noise high                  # an arena: the carrot e-puck in the DFT paper's Z-maze
  swarm sense zmaze --pose 0.2,0.5,0            # what a robot senses there
  swarm run office --controller fingerprint     # the scout maps the office floor with fingerprints of places
  swarm experiment fingerprint-localize         # map on one tour, localize on another (Tapus et al. 2006)
  swarm run zmaze --controller dft              # plan and act with dynamic neural fields (Billing et al. 2015)
  swarm experiment dft-case1                    # SPA beside follow the carrot on the paper's 100 pairs
  swarm run bg-exp1                             # the basal-ganglia animat survives (Girard et al. 2005)
  swarm up bg-colony                            # four animats, each its own process, sharing one map
  swarm run zmaze --controller my_pkg.mod:Mine  # your own controller class (docs/controllers.md)
  swarm check my_floor.toml                     # a scenario judged and its floor drawn to my_floor.png
  swarm bench {benchmarks}
  docker compose up swarm                       # the same in containers (compose.yaml, docs/docker.md)
"""


def _description() -> str:
    from swarm.bench import BENCHMARKS

    return DESCRIPTION_TEMPLATE.format(benchmarks=" | ".join(BENCHMARKS.names()))


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="swarm", description=_description(), formatter_class=argparse.RawDescriptionHelpFormatter
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    _add_run(sub)
    _add_experiment(sub)
    add_reproduce_parser(sub)
    add_sweep_parser(sub)
    _add_bench(sub)
    _add_world(sub)
    _add_agent(sub)
    _add_up(sub)
    _add_replay(sub)
    _add_report(sub)
    _add_monitor(sub)
    _add_status(sub)
    add_check_parsers(sub)
    _add_router(sub)
    add_credentials_parser(sub)
    _add_prepare(sub)
    for kind in WORLD_KINDS:  # a world kind's own commands (swarm sense); each sets its handler
        for add_command in kind.commands:
            resolve(add_command)(sub)
    sub.add_parser("scenarios", help="list presets and bundled scenarios")
    return parser


def _add_run(sub) -> None:
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
    run.add_argument("--agents", type=positive, help="number of agents (default: the scenario's)")
    run.add_argument("--controller", type=controller_name, metavar="NAME", help=CONTROLLER_HELP)
    run.add_argument("--seed", type=seed, help="seed of the map and of every random choice")
    _kind_options(run, titled=False)
    _kind_options(run, titled=True)
    _record_args(run, "write a rerun recording of the run to FILE (.rrd)")
    run.add_argument(
        "--until",
        choices=["foraged", "converged", "both"],
        default="foraged",
        help="foraged: every unit delivered (default); converged: marks equal the BFS "
        "distance on every reachable cell; both",
    )
    run.add_argument("--max-iterations", type=positive, default=1_000_000, metavar="M",
                     help="stop after M iterations if not done (default 1000000)")  # fmt: skip
    run.add_argument("--json", action="store_true", help="print one JSON object instead of text")


def _add_world(sub) -> None:
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
    world.add_argument("--start-with", type=positive, metavar="K",
                       help="start ticking once K agents have joined (default: --agents); more may join later, "
                       "up to --agents")  # fmt: skip
    world.add_argument("--max-misses", type=positive, default=3, metavar="K",
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
    credentials_arg(world, "`router` when it hosts the router, `world` with --connect")


def _add_agent(sub) -> None:
    agent = sub.add_parser(
        "agent",
        help="run agent process(es) that join a world",
        description="Join a world over zenoh and run one controller (or K with --count).",
    )
    agent.add_argument(
        "--controller", type=controller_name, default=DEFAULT_CONTROLLER, metavar="NAME", help=CONTROLLER_HELP
    )
    agent.add_argument(
        "--on-controller-error",
        choices=("idle", "stop"),
        default="idle",
        help="an arena controller that raises: its robot holds still (idle) or the process stops",
    )
    _client_args(agent)
    agent.add_argument("--count", type=positive, default=1, metavar="K", help="independent agents in this process")
    agent.add_argument("--null", action="store_true", help=argparse.SUPPRESS)  # benchmark floor
    agent.add_argument("--ids-file", help=argparse.SUPPRESS)  # swarm up: where the agents' ids go once joined
    agent.add_argument("--join-timeout", type=float, default=60.0, metavar="S",
                       help="give up when no world has answered within S seconds (default 60)")  # fmt: skip


def _add_up(sub) -> None:
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
    loss = up.add_mutually_exclusive_group()
    loss.add_argument("--respawn", action="store_true",
                      help="an agent process that dies mid-run is replaced: the same command again, whose agents "
                      "take the lost ones' places (by default the run goes on without them)")  # fmt: skip
    loss.add_argument(
        "--strict", action="store_true", help="an agent process that dies stops the whole run (exit status 2)"
    )
    up.add_argument("--max-respawns", type=positive, metavar="K",
                    help="with --respawn: replace the agents of one process at most K times (default 3); a "
                    "replacement that dies before its agents joined is not replaced")  # fmt: skip
    up_args(up)


def _add_replay(sub) -> None:
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


def _add_report(sub) -> None:
    rep = sub.add_parser(
        "report",
        help="summary and plots from a recording",
        description="Read a recording back and print the run summary; write plots (delivered, share of "
        "optimal cells, agents per state vs tick) and summary.json.",
    )
    rep.add_argument("file", metavar="FILE", help="a .rrd written by swarm up or swarm run --record")
    rep.add_argument("--out", metavar="DIR", help="where the plots go (default: FILE without .rrd)")
    rep.add_argument("--json", action="store_true", help="print one JSON object instead of text")


def _add_monitor(sub) -> None:
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


def _add_status(sub) -> None:
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


def _add_router(sub) -> None:
    router = sub.add_parser(
        "router",
        help="run a bare zenoh router (for worlds and agents on several hosts)",
        description="Run a zenoh router that worlds (--connect), agents and monitors join; multicast "
        "scouting stays off, so every process names the router's endpoint.",
    )
    router.add_argument("--listen", default="tcp/0.0.0.0:7447", metavar="ENDPOINT",
                        help="where to listen (default tcp/0.0.0.0:7447)")  # fmt: skip
    router.add_argument("--mesh", action="append", default=[], type=_mesh_endpoint, metavar="ENDPOINT",
                        help="link to every other router this name resolves to, e.g. tcp/router:7447 for a "
                        "Docker Swarm service with endpoint_mode dnsrr or a Kubernetes headless service "
                        "(repeat it for more names; docs/deploy.md)")  # fmt: skip
    credentials_arg(router, "`router`: check logins and enforce the access rules")


def _mesh_endpoint(text: str) -> str:
    from swarm.core.mesh import split

    try:
        split(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


def _add_prepare(sub) -> None:
    prep = sub.add_parser(
        "prepare",
        help="compile the kernels and the agents' step now, so runs start at once",
        description="Compile (once per source version, ~1-2 minutes on 2 cores) the engine, world and "
        "controller kernels and the agents' ahead-of-time step into ~/.cache/swarm (or $XDG_CACHE_HOME). "
        "swarm up does it by itself; container images do it at build time.",
    )
    prep.add_argument("--require-aot", action="store_true",
                      help="fail if the ahead-of-time build cannot be made (no C compiler)")  # fmt: skip


def _add_experiment(sub) -> None:
    from swarm.experiments import EXPERIMENTS

    exp = sub.add_parser(
        "experiment",
        help="reproduce a table of the paper",
        description="Rerun one of the paper's experiments (or the congestion study, which adds robot bodies "
        "to Table 1) and write runs.csv, summary.csv, table.md (paper beside ours) and plot.png.",
    )
    exp.add_argument("name", choices=EXPERIMENTS.names(), metavar="NAME",
                     help="; ".join(f"{e.name}: {e.description}" for e in EXPERIMENTS))  # fmt: skip
    exp.add_argument("--reps", type=positive, help="runs per configuration (default per experiment)")
    _add_entry_options(exp, EXPERIMENTS)
    exp.add_argument("--jobs", type=positive, help="workers (default: all cores, or the Ray cluster's CPUs)")
    add_executor_options(exp)
    exp.add_argument("--seed", type=seed, default=0, help="first seed (runs use seed..seed+reps-1)")
    exp.add_argument("--out", type=Path, help="output folder (default results/NAME)")


def _add_bench(sub) -> None:
    from swarm.bench import BENCHMARKS

    bench = sub.add_parser("bench", help="measure throughput", description="Measure throughput.")
    bench.add_argument("target", choices=BENCHMARKS.names(),
                       help="; ".join(f"{b.name}: {b.description}" for b in BENCHMARKS))  # fmt: skip
    bench.add_argument("--json", action="store_true", help="print one JSON object")
    bench.add_argument("--quick", action="store_true", help="shorter measurement")
    _add_entry_options(bench, BENCHMARKS)


def _entry_options(registry: Registry) -> dict[str, tuple[Option, list[str], dict[str, list[str]]]]:
    """Every option the registry's entries declare, by flag: (the first declaration, who takes it,
    who says what of it: help text -> entries)."""
    found: dict[str, tuple[Option, list[str], dict[str, list[str]]]] = {}
    for entry in registry:
        for option in entry.options:
            _, takers, said = found.setdefault(option.flag, (option, [], {}))
            takers.append(entry.name)
            said.setdefault(option.help, []).append(entry.name)
    return found


def _add_entry_options(parser: argparse.ArgumentParser, registry: Registry) -> None:
    """The options the entries declare; each one's help says who takes it, with that entry's words."""
    for flag, (option, _, said) in _entry_options(registry).items():
        help_text = "; ".join(f"{' | '.join(names)}: {text}" for text, names in said.items())
        kw = {"dest": option.keyword, "help": help_text, "metavar": option.metavar, "default": option.default}
        if option.type is not None:
            kw["type"] = resolve(option.type)
        if option.choices is not None:
            kw["choices"] = list(option.choices)
        parser.add_argument(flag, action="append" if option.repeat else "store", **kw)


def _chosen_options(args, registry: Registry, entry) -> dict:
    """The values of `entry`'s own options; one it does not take, given anyway, is a one-line error."""
    mine = {o.flag for o in entry.options}
    out = {}
    for flag, (option, takers, _) in _entry_options(registry).items():
        value = getattr(args, option.keyword)
        if flag not in mine:
            if value is not None and value != option.default:
                raise ScenarioError("command line", flag, f"this is for {' | '.join(takers)}")
            continue
        out[option.keyword] = resolve(option.collect)(value) if option.collect else value
    return out


def _client_args(p: argparse.ArgumentParser) -> None:
    """Where a client of a running world finds it: agents, monitor, status."""
    p.add_argument("--connect", default="tcp/127.0.0.1:7447", metavar="ENDPOINT", help="the router")
    p.add_argument("--run-id", default="default", help="the world's run id (default: default)")
    credentials_arg(
        p, "`agent<i>` for agent process i, or DIR/agent-pool to claim a free one; `monitor` for monitor and status"
    )


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


def _kind_options(p: argparse.ArgumentParser, titled: bool) -> None:
    """The world kinds' run options: those without a title of their own among the command's
    options, or those with one, each kind's in its own section."""
    for kind in WORLD_KINDS:
        if kind.options is not None and (kind.options_title is not None) == titled:
            resolve(kind.options)(p.add_argument_group(kind.options_title) if titled else p)


def _scenario_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("scenario", metavar="SCENARIO", help=f"a TOML file, a preset ({PRESET_HELP}) or a bundled name")
    p.add_argument("--agents", type=positive, help="number of agents (default: the scenario's)")
    p.add_argument("--controller", type=controller_name, metavar="NAME", help=CONTROLLER_HELP)
    p.add_argument("--seed", type=seed, help="seed of the map and of every random choice")
    _kind_options(p, titled=False)
    p.add_argument("--until", choices=["foraged", "converged", "both"], default="foraged", help="when the run ends")
    p.add_argument("--max-iterations", type=positive, default=1_000_000, metavar="M", help="stop after M ticks")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of text")
    _kind_options(p, titled=True)


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    signal.signal(signal.SIGTERM, raise_interrupt)
    try:
        with use(executor_for(args)):  # where batch_run runs the command's runs (--executor)
            return (COMMANDS.get(args.command) or args.handler)(args)
    except (ScenarioError, RecordingError, StateError) as exc:
        print(f"swarm: error: {exc}", file=sys.stderr)
        return 2
    except (ConnectionError, TimeoutError, RunError) as exc:
        print(f"swarm: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("swarm: interrupted", file=sys.stderr)
        return 130


def resolve_scenario(args, loaded=None):
    """The scenario the command line names (or `loaded`, already read) with its options applied."""
    scenario = loaded if loaded is not None else load_scenario(args.scenario)
    common = {"agents": args.agents, "controller": args.controller, "seed": args.seed}
    return resolve(kind_of(scenario).overrides)(scenario, args, common)


def _check(scenario, until: str) -> None:
    """A run the world kind refuses before its processes start (the grid: an end rule its controller
    cannot reach)."""
    if (check := kind_of(scenario).check) is not None:
        resolve(check)(scenario, until)


def cmd_world(args) -> int:
    from swarm.world_process import serve

    scenario = resolve_scenario(args)
    _check(scenario, args.until)
    summary = serve(scenario, args.run_id, args.summary_file, quiet=args.quiet,
                    listen=None if args.connect else args.listen,
                    connect=args.connect, deadline=args.deadline, max_misses=args.max_misses, until=args.until,
                    start_with=args.start_with,
                    max_iterations=args.max_iterations, linger=args.linger,
                    start_timeout=args.start_timeout, null=args.null,
                    state_dir=args.state_dir, persist_every=args.persist_every, mode=args.mode,
                    rate=args.rate, record=args.record, viewer=_viewer_url(args.viewer),
                    identity=identity(args))  # fmt: skip
    return _print_any(summary, args.json, args.until)


def cmd_agent(args) -> int:
    from agents.runtime import JoinRefused
    from agents.runtimes import make_runtime
    from swarm.core.wire import ENDED

    try:
        runtime = make_runtime(args.run_id, args.controller, args.connect, args.count, null=args.null,
                               join_timeout=args.join_timeout, on_error=args.on_controller_error,
                               ids_file=args.ids_file, identity=agent_identity(args))  # fmt: skip
    except JoinRefused as exc:
        print(f"swarm: {exc}", file=sys.stderr)
        return 0 if ENDED in str(exc) else 2  # a late agent of a finished run has nothing to do
    try:
        runtime.run()
    finally:
        runtime.close()
        if line := runtime.rejections_line():
            print(line, file=sys.stderr)
    return 0


def cmd_up(args) -> int:
    from swarm.launcher import MAX_RESPAWNS, swarm_up
    from world_server.server import new_run_id

    if args.max_respawns is not None and not args.respawn:
        raise ScenarioError("command line", "--max-respawns", "needs --respawn")
    scenario = resolve_scenario(args)
    _check(scenario, args.until)
    run_id = args.run_id or new_run_id()
    record = None if args.no_record else (args.record or f"runs/{run_id}.rrd")
    kind_options = resolve(kind_of(scenario).up_options)(scenario, args)  # its controller, bodies, world options
    summary = swarm_up(args.scenario, scenario.agents, seed=args.seed, run_id=run_id, listen=args.listen,
                       until=args.until, max_iterations=args.max_iterations, deadline=args.deadline,
                       progress=not args.json and sys.stderr.isatty(), mode=args.mode, rate=args.rate,
                       record=record, viewer=args.viewer, secure=args.secure, credentials=args.credentials,
                       on_loss="strict" if args.strict else "respawn" if args.respawn else "go-on",
                       max_respawns=args.max_respawns or MAX_RESPAWNS, **kind_options)  # fmt: skip
    if summary.get("recording"):
        _point_at_recording(summary["recording"])
    return _print_any(summary, args.json, args.until)


def _print_any(summary: dict, as_json: bool, until: str) -> int:
    """The summary as its world kind prints it; the exit status (0: finished)."""
    return resolve(kind_of(summary).print_summary)(summary, as_json, until)


def cmd_run(args) -> int:
    scenario = resolve_scenario(args)
    kind = kind_of(scenario)
    summary = resolve(kind.run)(scenario, args, _viewer_url(args.viewer) if args.record else None)
    if args.record:
        _point_at_recording(args.record)
    return resolve(kind.print_summary)(summary, args.json, args.until)


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
    from swarm.experiments import EXPERIMENTS

    spec = EXPERIMENTS[args.name]
    options = _chosen_options(args, EXPERIMENTS, spec)
    result = resolve(spec.run)(spec.name, reps=args.reps, jobs=args.jobs, seed=args.seed, out=args.out, **options)
    print(result["markdown"])
    print(f"wrote {result['out']}/{spec.writes}")
    return 0


def cmd_bench(args) -> int:
    from swarm.bench import BENCHMARKS

    spec = BENCHMARKS[args.target]
    result = resolve(spec.run)(quick=args.quick, **_chosen_options(args, BENCHMARKS, spec))
    print(json.dumps(result) if args.json else resolve(spec.report)(result))
    return 0


def cmd_monitor(args) -> int:
    from swarm.monitor import monitor

    summary = monitor(args.connect, args.run_id, progress=not args.json and sys.stderr.isatty(),
                      log_every=args.log_every, start_timeout=args.start_timeout, identity=identity(args))  # fmt: skip
    return _print_any(summary, args.json, summary.get("until", "foraged"))


def cmd_status(args) -> int:
    from swarm.monitor import status

    info = status(args.connect, args.run_id, router_only=args.router, timeout=args.timeout, identity=identity(args))
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
        done, total = kind_of(info).progress
        done = f"{done} {info[done]}/{info[total]}"
        print(f"run {args.run_id}: {state} at tick {info['iterations']}, {done}, {info['agents_alive']} agents alive")
    return 0


def cmd_router(args) -> int:
    from swarm.monitor import serve_router

    serve_router(args.listen, identity(args), tuple(args.mesh))
    return 0


def cmd_prepare(args) -> int:
    from swarm.launcher import prepare

    aot_built = prepare(progress=True, engine=True, every_kind=True)
    print(f"swarm: kernels compiled; agents' ahead-of-time step: {'built' if aot_built else 'MISSING (JIT fallback)'}")
    return 0 if aot_built or not args.require_aot else 1


def cmd_scenarios(args) -> int:
    print(f"presets: {PRESET_HELP}")
    print(f"bundled: {', '.join(bundled_scenarios())}  (in {Path(__file__).parent / 'scenarios'})")
    return 0


COMMANDS = {"run": cmd_run, "experiment": cmd_experiment, "bench": cmd_bench, "scenarios": cmd_scenarios,
            "world": cmd_world, "agent": cmd_agent, "up": cmd_up, "replay": cmd_replay,
            "report": cmd_report, "monitor": cmd_monitor, "status": cmd_status, "router": cmd_router,
            "prepare": cmd_prepare, "reproduce": cmd_reproduce}  # fmt: skip


if __name__ == "__main__":
    sys.exit(main())
