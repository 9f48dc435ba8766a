"""`swarm check FILE` and `swarm schema`: a scenario judged and drawn before it runs, and the JSON
Schema editors validate scenario files with as they are typed."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from swarm.scenario import load_scenario, scenario_schema


def add_check_parsers(sub) -> None:
    check = sub.add_parser(
        "check",
        help="check a scenario file and draw its floor",
        description="Read a scenario as every command does (the same parser: one line says what is wrong and "
        "where), print what it holds, and draw its floor to a PNG.",
    )
    check.add_argument("scenario", metavar="SCENARIO", help="a TOML file, a preset or a bundled name")
    check.add_argument("--png", type=Path, metavar="FILE", help="where to draw the floor (default: SCENARIO.png "
                       "beside a file, or NAME.png here)")  # fmt: skip
    check.add_argument("--json", action="store_true", help="print what it holds as one JSON object")
    check.set_defaults(handler=cmd_check)
    schema = sub.add_parser(
        "schema",
        help="print the JSON Schema of scenario files",
        description="The JSON Schema of scenario files (every world kind), made from the parsers' own tables and "
        "the registries (controllers, sensors, robot models).  An editor that reads JSON Schema for TOML "
        "(Even Better TOML, taplo) validates and completes a file whose first line is `#:schema PATH`.",
    )
    schema.add_argument("--out", type=Path, metavar="FILE", help="write it here instead of printing it")
    schema.add_argument("--package-only", action="store_true", help="leave out the controllers and sensors "
                        "of installed packages (the schema swarm carries: "
                        "swarm/scenarios/scenario.schema.json)")  # fmt: skip
    schema.set_defaults(handler=cmd_schema)


def cmd_check(args: argparse.Namespace) -> int:
    from swarm.review.floor import draw_floor

    scenario = load_scenario(args.scenario)
    source = Path(args.scenario)
    png = args.png or (source.with_suffix(".png") if source.suffix == ".toml" else Path(f"{scenario.name}.png"))
    draw_floor(scenario, png)
    held = scenario.describe()
    if args.json:
        print(json.dumps({"scenario": held, "png": str(png)}))
    else:
        print(f"{args.scenario}: a valid {'arena' if hasattr(scenario, 'walls') else 'grid'} scenario "
              f"'{scenario.name}' ({held.get('agents', '?')} agents); its floor: {png}")  # fmt: skip
    return 0


def cmd_schema(args: argparse.Namespace) -> int:
    text = json.dumps(scenario_schema(installed=not args.package_only), indent=1, sort_keys=True) + "\n"
    if args.out is None:
        sys.stdout.write(text)
    else:
        args.out.write_text(text)
        print(f"schema: {args.out}", file=sys.stderr)
    return 0
