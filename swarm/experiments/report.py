"""The pieces every paper's reproduction report shares: its markdown tables, its header stating the
seeds and the verdict rule, its claims as summary.csv rows and the tally of verdicts."""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence

from swarm.experiments import protocol as P

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
