"""The reproduction protocol: which seeds a number may come from, and how a claim of a paper is judged.

Seeds come in two declared ranges.  The development range is where anything may be tried (tuning,
debugging, the smoke runs of the tests); the confirmation range is used only for reported numbers, so
no reported number was seen while a parameter was chosen.  A claim of the paper names the direction
it expects (one condition higher, lower, or no difference); its verdict is read off our test by one
rule (`verdict`), never by eye.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from swarm.experiments.stats import Comparison

DEVELOPMENT_SEEDS = range(0, 10_000)
CONFIRMATION_SEEDS = range(10_000, 20_000)
ALPHA = 0.05

REPRODUCED = "reproduced"
SAME_DIRECTION = "same direction, not significant"
NOT_REPRODUCED = "not reproduced"
REVERSED = "reversed"


def seed_range(confirm: bool) -> range:
    """The seeds of the confirmation range (reported numbers) or the development range (anything else)."""
    return CONFIRMATION_SEEDS if confirm else DEVELOPMENT_SEEDS


def seeds(n: int, confirm: bool, offset: int = 0) -> range:
    """n consecutive seeds from the start (plus `offset`) of the chosen range; refuses to spill out of it."""
    pool = seed_range(confirm)
    if not (offset >= 0 and n >= 0 and offset + n <= len(pool)):
        raise ValueError(f"{n} seeds from offset {offset} do not fit the {len(pool)} seeds of the range")
    return range(pool.start + offset, pool.start + offset + n)


def is_confirmation(seed: int) -> bool:
    return seed in CONFIRMATION_SEEDS


def verdict(expected: int, test: Comparison, alpha: float = ALPHA) -> str:
    """The verdict on a claim that expects `expected` (+1: the first condition higher or more often true,
    -1: lower, 0: no difference) from our test of it.

    A directional claim is *reproduced* when the effect has the expected sign and p < alpha; *same
    direction, not significant* when the sign agrees but p >= alpha; *reversed* when the sign is the
    opposite and p < alpha; otherwise *not reproduced*.  A claim of no difference is reproduced when
    p >= alpha (our test found none: absence of evidence, reported with its interval) and not
    reproduced when p < alpha.
    """
    if expected not in (-1, 0, 1):
        raise ValueError("expected is +1, -1 or 0")
    if math.isnan(test.p) or math.isnan(test.effect):
        return NOT_REPRODUCED
    significant = test.p < alpha
    if expected == 0:
        return NOT_REPRODUCED if significant else REPRODUCED
    agrees = test.effect * expected > 0
    if agrees:
        return REPRODUCED if significant else SAME_DIRECTION
    return REVERSED if significant and test.effect != 0 else NOT_REPRODUCED


@dataclass(frozen=True)
class Claim:
    """One claim of a paper beside our measurement of it."""

    text: str  # the claim, in the paper's words or close to them
    paper: str  # the paper's number(s), as printed there
    ours: str  # our number(s), with intervals (Estimate.text)
    test: Comparison | None = None  # None: a descriptive number with no claim to test
    expected: int = 1

    @property
    def verdict(self) -> str:
        return verdict(self.expected, self.test) if self.test is not None else "–"


def claims_table(claims: Sequence[Claim]) -> str:
    """The paper's claims beside ours, as a markdown table: n, the test, p, the effect and the verdict."""
    lines = ["| claim | paper | ours (95% CI) | n | test | p | effect | verdict |", "|---|---|---|---|---|---|---|---|"]
    for c in claims:
        t = c.test
        test = (t.name, str(t.n), p_text(t.p), f"{t.effect:+.3g} ({t.effect_name})") if t else ("–", "", "", "")
        lines.append(f"| {c.text} | {c.paper} | {c.ours} | {test[1]} | {test[0]} | {test[2]} | {test[3]} | "
                     f"{c.verdict} |")  # fmt: skip
    return "\n".join(lines) + "\n"


def p_text(p: float) -> str:
    """A p value as the reports print it ("n/a" where no test could be made)."""
    if math.isnan(p):
        return "n/a"
    return "< 0.001" if p < 0.001 else f"{p:.3f}"
