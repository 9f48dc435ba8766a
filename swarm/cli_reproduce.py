"""`swarm reproduce PAPER`: every experiment of a paper on the confirmation seeds, one report."""

from __future__ import annotations

import argparse
from pathlib import Path

from swarm.core.registry import resolve
from swarm.core.tables import positive
from swarm.experiments.executors import add_executor_options


def add_reproduce_parser(sub) -> None:
    from swarm.experiments import PAPERS

    rep = sub.add_parser(
        "reproduce",
        help="run a paper's experiments on the confirmation seeds and write its report",
        description="Run every experiment of a paper on the confirmation seeds (10000 on; tuning uses 0-9999) "
        "and write one report: each claim of the paper beside ours with n, a 95% confidence interval and a "
        "verdict, the tables, plots and CSVs.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="papers:\n" + "\n".join(f"  {p.name:12} {p.title} (results of {p.page})" for p in PAPERS),
    )
    rep.add_argument("paper", choices=(*PAPERS.names(), "all"), metavar="PAPER",
                     help=f"{', '.join(PAPERS.names())} or all")  # fmt: skip
    rep.add_argument("--quick", action="store_true", help="a few runs per condition: checks that it all runs")
    rep.add_argument("--jobs", type=positive, help="workers (default: all cores, or the Ray cluster's CPUs)")
    add_executor_options(rep)
    rep.add_argument("--out", type=Path, help="output folder (default results/reproduce/PAPER; with all, "
                     "one subfolder per paper)")  # fmt: skip


def cmd_reproduce(args) -> int:
    from swarm.experiments import PAPERS
    from swarm.experiments.report import write_index

    papers = list(PAPERS) if args.paper == "all" else [PAPERS[args.paper]]
    roots = set()
    for spec in papers:
        out = args.out if args.out is None or len(papers) == 1 else args.out / spec.name
        result = resolve(spec.reproduce)(quick=args.quick, jobs=args.jobs, out=out)
        verdicts = ", ".join(f"{n} {v}" for v, n in result["verdicts"].items())
        print(f"{spec.name}: {result['claims']} claims: {verdicts}; report: {result['out']}/report.md")
        roots.add(Path(result["out"]).parent)
    for root in roots:  # the folder holding the reports: its index counts them all
        write_index(root)
    return 0
