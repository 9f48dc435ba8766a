"""The pieces every paper's reproduction report shares: its markdown tables, its header stating the
seeds and the verdict rule, its claims as summary.csv rows and the tally of verdicts."""

from __future__ import annotations

import csv
from collections import Counter
from collections.abc import Mapping, Sequence
from pathlib import Path

from agents.controllers import CONTROLLERS
from swarm.core.params import SOURCES, provenance, provenance_table
from swarm.core.registry import resolve
from swarm.experiments import PAPERS
from swarm.experiments import protocol as P

VERDICTS = (P.REPRODUCED, P.SAME_DIRECTION, P.NOT_REPRODUCED, P.REVERSED)
QUICK_BANNER = "**Quick run: too few runs to be evidence; it checks that everything runs.**"
VERDICT_RULE = (
    "Verdicts follow one rule (swarm/experiments/protocol.py): the expected direction with p < 0.05 is "
    "*reproduced*, without it *same direction, not significant*; the opposite direction with p < 0.05 "
    "is *reversed*, without it *not reproduced*; a claim of no difference is reproduced when p >= 0.05."
)


def markdown_table(header: Sequence[str], lines: Sequence[Sequence[str]]) -> str:
    """A markdown table of `header` and rows of already formatted cells."""
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return "\n".join(out + ["| " + " | ".join(line) + " |" for line in lines]) + "\n"


def seeds_text(reps: Mapping[str, int]) -> str:
    """Which confirmation seeds each experiment used, e.g. "table1: 10000..10999"."""
    first = P.CONFIRMATION_SEEDS.start
    return ", ".join(f"{name}: {first}..{first + n - 1}" for name, n in reps.items())


def report_text(title: str, design: str, claims: Sequence[P.Claim], sections: Sequence[tuple[str, str]],
                reps: Mapping[str, int], quick: bool) -> str:  # fmt: skip
    """The report: title, the quick banner where it applies, the seeds, the design (how conditions are
    paired, which intervals), the verdict rule, the claims table, then each (title, markdown) section."""
    intro = (QUICK_BANNER + "\n" if quick else "") + f"Seeds from the confirmation range only ({seeds_text(reps)}). "
    lines = [f"# {title}: the reproduction", "", intro + design + " " + VERDICT_RULE, "", "## Claims", "",
             P.claims_table(claims)]  # fmt: skip
    for heading, body in sections:
        lines += [f"## {heading}", "", body, ""]
    return "\n".join(lines)


def claim_row(c: P.Claim) -> dict:
    """One row of summary.csv."""
    t = c.test
    return {"claim": c.text, "paper": c.paper, "ours": c.ours, "test": t.name if t else "", "n": t.n if t else "",
            "p": t.p if t else "", "effect": t.effect if t else "", "verdict": c.verdict}  # fmt: skip


def tally(claims: Sequence[P.Claim]) -> dict[str, int]:
    """How many claims got each verdict."""
    return dict(Counter(c.verdict for c in claims))


def parameter_classes(controllers: Sequence[str]) -> list[type]:
    """The parameter classes the controllers declare (ControllerSpec.parameters), each once, in order."""
    seen: dict[str, type] = {}
    for name in controllers:
        for ref in CONTROLLERS[name].parameters:
            seen.setdefault(ref, resolve(ref))
    return list(seen.values())


def parameters_page(title: str, controllers: Sequence[str], protocol: Sequence[type] = ()) -> str:
    """parameters.md: every parameter the report's runs use, with its value and provenance: the controllers'
    classes, then the `protocol`'s (an experiment's own declared numbers, such as how a map is made)."""
    parts = [f"# {title}: the declared parameters", "",
             "Every value the report's runs use unless an experiment says otherwise, with its provenance: "
             "the paper's (where it gives it), the original code's, or ours with the reason "
             "(swarm/core/params.py).", ""]  # fmt: skip
    for cls in (*parameter_classes(controllers), *protocol):
        doc = " ".join((cls.__doc__ or "").strip().split("\n\n")[0].split())  # its first paragraph
        parts += [f"## {cls.__name__} ({cls.__module__})", "", doc, "", provenance_table(cls), ""]
    return "\n".join(parts)


def parameters_section(controllers: Sequence[str], protocol: Sequence[type] = ()) -> tuple[str, str]:
    """The report's section on its parameters: how many come from where, and a link to parameters.md."""
    classes = (*parameter_classes(controllers), *protocol)
    counts = Counter(p.source or "undeclared" for cls in classes for p in provenance(cls))
    said = ", ".join(f"{counts[s]} {s}" for s in (*SOURCES, "undeclared") if counts[s])
    return "Parameters", (f"{sum(counts.values())} parameters ({said}; controllers: {', '.join(controllers)}), "
                          "one declared set for every experiment: [parameters.md](parameters.md).")  # fmt: skip


def write_index(root: Path) -> Path:
    """root/index.md: every paper's report found under `root`, its verdicts counted from its summary.csv,
    so a page of results (the README's) can link one table that `swarm reproduce` keeps up to date."""
    lines = []
    for spec in PAPERS:
        summary = root / spec.name / "summary.csv"
        if not summary.is_file():
            continue
        with open(summary, newline="") as f:
            counts = Counter(row["verdict"] for row in csv.DictReader(f))
        quick = QUICK_BANNER in (root / spec.name / "report.md").read_text()
        lines.append([f"[{spec.title}]({spec.name}/report.md)" + (" (quick run: not evidence)" if quick else ""),
                      str(sum(counts.values())), *(str(counts[v]) for v in (*VERDICTS, "–"))])  # fmt: skip
    text = ("# Reproductions\n\nEach paper's claims judged by `swarm reproduce` on confirmation seeds "
            "(swarm/experiments/protocol.py); the reports give n, the 95% intervals and the tests.\n\n"
            + markdown_table(["paper", "claims", *VERDICTS, "descriptive (no test)"], lines))  # fmt: skip
    (root / "index.md").write_text(text)
    return root / "index.md"
