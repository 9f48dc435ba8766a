"""The statistics every reproduction reports, from scipy.stats (and statsmodels where only it has the test).

Estimates carry their 95% confidence interval and n; tests carry their statistic, p-value and an
effect size with its sign, so a claim's verdict can be read off them (`swarm.experiments.protocol`).
Which test fits depends on the design: conditions that share seeds and maps are paired (McNemar,
Wilcoxon signed-rank, Cochran-Mantel-Haenszel over strata); runs stopped at a cap are censored
(Kaplan-Meier, log-rank), never averaged in as if they had finished.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

CONFIDENCE = 0.95
RESAMPLES = 9_999


@dataclass(frozen=True)
class Estimate:
    """A number with its 95% confidence interval over n observations (bounds nan where n is too small)."""

    value: float
    low: float
    high: float
    n: int
    what: str = "mean"

    def text(self, digits: int = 3) -> str:
        """'value [low, high]' to `digits` significant digits (whole numbers in full from 10**digits up)."""
        if math.isnan(self.value):
            return "n/a"
        if math.isnan(self.low):
            return number(self.value, digits)
        return f"{number(self.value, digits)} [{number(self.low, digits)}, {number(self.high, digits)}]"

    def percent(self, unit: str = "%", digits: int = 3) -> str:
        """A share (or a difference of shares) as percentages (points), 'value [low, high]' and `unit`;
        "n/a" alone where there is no value."""
        scaled = Estimate(100 * self.value, 100 * self.low, 100 * self.high, self.n, self.what)
        return scaled.text(digits) + ("" if math.isnan(self.value) else unit)


def number(x: float, digits: int = 3) -> str:
    """x to `digits` significant digits, or as a whole number with thousands separated once it has more."""
    if math.isnan(x):
        return "n/a"
    return f"{x:,.0f}" if abs(x) >= 10**digits else f"{x:.{digits}g}"


@dataclass(frozen=True)
class Comparison:
    """A hypothesis test: its name, statistic, two-sided p-value, and an effect size whose sign says
    which way the data lean (positive: the first condition higher, or more often true)."""

    name: str
    statistic: float
    p: float
    effect: float
    effect_name: str
    n: int


def _finite(x: Sequence[float]) -> np.ndarray:
    a = np.asarray(x, dtype=float)
    return a[np.isfinite(a)]


def _bootstrap(x: np.ndarray, statistic, what: str, seed: int) -> Estimate:
    from scipy.stats import bootstrap

    value = float(statistic(x))
    if len(x) < 3 or np.all(x == x[0]):  # no spread to resample: the interval is the value itself, or unknown
        bound = value if len(x) >= 3 else math.nan
        return Estimate(value, bound, bound, len(x), what)
    res = bootstrap((x,), statistic, confidence_level=CONFIDENCE, n_resamples=RESAMPLES, method="BCa",
                    random_state=np.random.default_rng(seed))  # fmt: skip
    low, high = res.confidence_interval
    return Estimate(value, float(low), float(high), len(x), what)


def mean_ci(x: Sequence[float], seed: int = 0) -> Estimate:
    """The mean with its bias-corrected bootstrap interval (non-finite values left out)."""
    a = _finite(x)
    if not len(a):
        return Estimate(math.nan, math.nan, math.nan, 0)
    return _bootstrap(a, np.mean, "mean", seed)


def median_ci(x: Sequence[float], seed: int = 0) -> Estimate:
    """The median with its bootstrap interval (non-finite values left out)."""
    a = _finite(x)
    if not len(a):
        return Estimate(math.nan, math.nan, math.nan, 0, "median")
    return _bootstrap(a, np.median, "median", seed)


def proportion_ci(successes: int, n: int) -> Estimate:
    """k of n with its Wilson score interval (good at small n and near 0 or 1, unlike the normal one)."""
    from scipy.stats import binomtest

    if n == 0:
        return Estimate(math.nan, math.nan, math.nan, 0, "proportion")
    ci = binomtest(successes, n).proportion_ci(confidence_level=CONFIDENCE, method="wilson")
    return Estimate(successes / n, float(ci.low), float(ci.high), n, "proportion")


def anova(groups: Sequence[Sequence[float]]) -> Comparison:
    """Independent groups of one continuous outcome: the one-way ANOVA (scipy's f_oneway), the test
    papers often report.  Effect: eta squared, the share of the variance between the groups."""
    from scipy.stats import f_oneway

    xs = [_finite(g) for g in groups]
    xs = [x for x in xs if len(x) > 1]
    n = sum(len(x) for x in xs)
    if len(xs) < 2:
        return Comparison("one-way ANOVA", math.nan, math.nan, math.nan, "eta squared", n)
    res = f_oneway(*xs)
    every = np.concatenate(xs)
    between = sum(len(x) * (x.mean() - every.mean()) ** 2 for x in xs)
    total = float(((every - every.mean()) ** 2).sum())
    return Comparison("one-way ANOVA", float(res.statistic), float(res.pvalue), between / total if total else 0.0,
                      "eta squared", n)  # fmt: skip


def mcnemar(a: Sequence[bool], b: Sequence[bool]) -> Comparison:
    """Paired binary outcomes (the same seeds and maps under two conditions): the exact McNemar test on the
    discordant pairs.  Effect: the difference of the proportions, a minus b."""
    from scipy.stats import binomtest

    x, y = np.asarray(a, bool), np.asarray(b, bool)
    only_a, only_b = int(np.sum(x & ~y)), int(np.sum(~x & y))
    p = binomtest(only_a, only_a + only_b).pvalue if only_a + only_b else 1.0
    return Comparison("McNemar (exact)", float(only_a), float(p), (only_a - only_b) / len(x) if len(x) else math.nan,
                "difference of proportions", len(x))  # fmt: skip


def fisher(successes_a: int, n_a: int, successes_b: int, n_b: int) -> Comparison:
    """Independent binary outcomes: Fisher's exact test.  Effect: the difference of the proportions, a minus b."""
    from scipy.stats import fisher_exact

    table = [[successes_a, n_a - successes_a], [successes_b, n_b - successes_b]]
    odds, p = fisher_exact(table)
    effect = successes_a / n_a - successes_b / n_b if n_a and n_b else math.nan
    return Comparison("Fisher exact", float(odds), float(p), effect, "difference of proportions", n_a + n_b)


def cochran_mantel_haenszel(strata: Sequence[tuple[int, int, int, int]]) -> Comparison:
    """Binary outcomes of two conditions within strata (a map, a seed block), each stratum as
    (successes a, n a, successes b, n b): the CMH test of a common odds ratio of 1 (statsmodels).
    Effect: the log of the pooled (Mantel-Haenszel) odds ratio, positive where a succeeds more often."""
    from statsmodels.stats.contingency_tables import StratifiedTable

    tables = [np.array([[sa, na - sa], [sb, nb - sb]], float) for sa, na, sb, nb in strata]
    st = StratifiedTable(tables)
    res = st.test_null_odds(correction=True)
    with np.errstate(divide="ignore"):
        effect = float(np.log(st.oddsratio_pooled))
    n = int(sum(na + nb for _, na, _, nb in strata))
    return Comparison("Cochran-Mantel-Haenszel", float(res.statistic), float(res.pvalue), effect,
                      "log pooled odds ratio", n)  # fmt: skip


def wilcoxon_paired(a: Sequence[float], b: Sequence[float]) -> Comparison:
    """Paired continuous outcomes: the Wilcoxon signed-rank test.  Effect: the matched-pairs rank-biserial
    correlation (from -1 to 1, positive where a is higher)."""
    from scipy.stats import rankdata, wilcoxon

    d = np.asarray(a, float) - np.asarray(b, float)
    d = d[np.isfinite(d) & (d != 0)]
    if not len(d):
        return Comparison("Wilcoxon signed-rank", 0.0, 1.0, 0.0, "rank-biserial", 0)
    res = wilcoxon(d)
    ranks = rankdata(np.abs(d))
    effect = float((ranks[d > 0].sum() - ranks[d < 0].sum()) / ranks.sum())
    return Comparison("Wilcoxon signed-rank", float(res.statistic), float(res.pvalue), effect, "rank-biserial", len(d))


def mann_whitney(a: Sequence[float], b: Sequence[float]) -> Comparison:
    """Independent continuous outcomes: the Mann-Whitney U test.  Effect: Cliff's delta (from -1 to 1,
    positive where a is higher), the rank-biserial correlation of U."""
    from scipy.stats import mannwhitneyu

    x, y = _finite(a), _finite(b)
    if not len(x) or not len(y):
        return Comparison("Mann-Whitney U", math.nan, math.nan, math.nan, "Cliff's delta", len(x) + len(y))
    res = mannwhitneyu(x, y, alternative="two-sided")
    effect = 2.0 * res.statistic / (len(x) * len(y)) - 1.0
    return Comparison("Mann-Whitney U", float(res.statistic), float(res.pvalue), float(effect), "Cliff's delta",
                len(x) + len(y))  # fmt: skip


def _censored(times: Sequence[float], finished: Sequence[bool]):
    from scipy.stats import CensoredData

    t, done = np.asarray(times, float), np.asarray(finished, bool)
    return CensoredData(uncensored=t[done], right=t[~done])


def kaplan_meier_median(times: Sequence[float], finished: Sequence[bool]) -> Estimate:
    """The median time to the event of runs some of which hit the cap (right-censored there), from the
    Kaplan-Meier curve, with the interval where its pointwise 95% band crosses one half; nan where the
    curve never falls to one half (more than half the runs capped)."""
    from scipy.stats import ecdf

    n = len(times)
    if not n:
        return Estimate(math.nan, math.nan, math.nan, 0, "KM median")
    sf = ecdf(_censored(times, finished)).sf
    t, s = sf.quantiles, sf.probabilities
    with warnings.catch_warnings():  # the band is undefined where S(t) is 0 or 1: those ends are not used
        warnings.simplefilter("ignore", RuntimeWarning)
        band = sf.confidence_interval(CONFIDENCE, method="log-log")

    def crossing(p: np.ndarray) -> float:
        below = np.flatnonzero(p <= 0.5)
        return float(t[below[0]]) if len(below) else math.nan

    return Estimate(crossing(s), crossing(band.low.probabilities), crossing(band.high.probabilities), n, "KM median")


def restricted_mean(times: Sequence[float], finished: Sequence[bool], horizon: float) -> float:
    """The mean time to the event restricted to `horizon` (the area under the Kaplan-Meier curve up to it):
    defined whatever share of the runs hit the cap, unlike the mean or the median.  The curve is known only up
    to the longest time observed, so the area stops there when the horizon lies beyond it."""
    from scipy.stats import ecdf

    if not len(times):
        return math.nan
    horizon = min(horizon, float(np.max(times)))
    sf = ecdf(_censored(times, finished)).sf
    t = np.concatenate([[0.0], sf.quantiles[sf.quantiles < horizon], [horizon]])
    s = np.concatenate([[1.0], sf.probabilities[sf.quantiles < horizon]])
    return float(np.sum(np.diff(t) * s))


def restricted_mean_ci(times: Sequence[float], finished: Sequence[bool], horizon: float,
                       seed: int = 0) -> Estimate:  # fmt: skip
    """The restricted mean time up to `horizon` (censored runs kept) with a percentile bootstrap interval
    over the runs."""
    from scipy.stats import bootstrap

    t, done = np.asarray(times, float), np.asarray(finished, bool)
    value = restricted_mean(t, done, horizon)
    if len(t) < 3 or np.all(t == t[0]):
        return Estimate(value, math.nan, math.nan, len(t), "restricted mean")
    res = bootstrap((t, done.astype(float)), lambda a, b: restricted_mean(a, b.astype(bool), horizon), paired=True,
                    vectorized=False, n_resamples=1999, method="percentile",
                    random_state=np.random.default_rng(seed))  # fmt: skip
    low, high = res.confidence_interval
    return Estimate(value, float(low), float(high), len(t), "restricted mean")


def logrank(times_a: Sequence[float], finished_a: Sequence[bool], times_b: Sequence[float],
            finished_b: Sequence[bool]) -> Comparison:  # fmt: skip
    """Two groups of censored times: the log-rank test.  Effect: the difference of the restricted mean
    times (a minus b) up to the shorter of the two groups' longest times, positive where a lasts longer."""
    from scipy.stats import logrank as scipy_logrank

    with warnings.catch_warnings():  # no event in either group: scipy divides 0 by 0, and the p-value is nan
        warnings.simplefilter("ignore", RuntimeWarning)
        res = scipy_logrank(_censored(times_a, finished_a), _censored(times_b, finished_b))
    horizon = float(min(np.max(times_a), np.max(times_b)))
    effect = restricted_mean(times_a, finished_a, horizon) - restricted_mean(times_b, finished_b, horizon)
    return Comparison("log-rank", float(res.statistic), float(res.pvalue), effect, "difference of restricted means",
                len(times_a) + len(times_b))  # fmt: skip


def ratio_of_means(a: Sequence[float], b: Sequence[float], paired: bool, null: float = 1.0,
                   seed: int = 0) -> tuple[Estimate, Comparison]:  # fmt: skip
    """mean(a) / mean(b) with its bootstrap interval (pairs resampled together when `paired`: the same seeds
    and maps), and a bootstrap test of ratio = `null`: p is twice the smaller tail of the resampled ratios
    beyond `null`.  Effect: the ratio minus `null`."""
    from scipy.stats import bootstrap

    x, y = np.asarray(a, float), np.asarray(b, float)
    value = float(x.mean() / y.mean()) if len(x) and len(y) else math.nan
    if len(x) < 3 or len(y) < 3:
        return (Estimate(value, math.nan, math.nan, len(x), "ratio of means"),
                Comparison("bootstrap ratio", value, math.nan, value - null, "ratio minus null", len(x)))  # fmt: skip

    def ratio(u, v, axis=-1):
        return np.mean(u, axis=axis) / np.mean(v, axis=axis)

    res = bootstrap((x, y), ratio, paired=paired, vectorized=True, confidence_level=CONFIDENCE,
                    n_resamples=RESAMPLES, method="percentile", random_state=np.random.default_rng(seed))  # fmt: skip
    dist = res.bootstrap_distribution
    p = min(1.0, 2.0 * min(float(np.mean(dist <= null)), float(np.mean(dist >= null))))
    low, high = res.confidence_interval
    n = len(x) if paired else len(x) + len(y)
    return (Estimate(value, float(low), float(high), n, "ratio of means"),
            Comparison("bootstrap ratio", value, p, value - null, "ratio minus null", n))  # fmt: skip


def spearman(x: Sequence[float], y: Sequence[float]) -> Comparison:
    """A monotone trend of y with x: Spearman's rank correlation (the effect, from -1 to 1) and its p-value."""
    from scipy.stats import spearmanr

    u, v = _paired_finite(x, y)
    if len(u) < 3:
        return Comparison("Spearman", math.nan, math.nan, math.nan, "rho", len(u))
    res = spearmanr(u, v)
    return Comparison("Spearman", float(res.statistic), float(res.pvalue), float(res.statistic), "rho", len(u))


def cochrans_q(outcomes: Sequence[Sequence[bool]]) -> Comparison:
    """Binary outcomes of k conditions on the same cases (one sequence per condition, case i in place i):
    Cochran's Q, the k-condition McNemar.  Effect: the first condition's share minus the last's."""
    from statsmodels.stats.contingency_tables import cochrans_q as q

    table = np.column_stack([np.asarray(o, bool) for o in outcomes]).astype(int)
    n = len(table)
    effect = float(table[:, 0].mean() - table[:, -1].mean()) if n else math.nan
    if n == 0 or np.all(table == table[:, :1]):  # every case alike across conditions: nothing to test
        return Comparison("Cochran's Q", 0.0, 1.0, effect, "difference of proportions", n)
    res = q(table)
    return Comparison("Cochran's Q", float(res.statistic), float(res.pvalue), effect, "difference of proportions", n)


def _paired_finite(x: Sequence[float], y: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    u, v = np.asarray(x, float), np.asarray(y, float)
    keep = np.isfinite(u) & np.isfinite(v)
    return u[keep], v[keep]


PAIRED_MIN = 8  # pairs below which a paired bootstrap gives no interval: resamples of fewer are often degenerate


def _paired_bootstrap(x: Sequence[float], y: Sequence[float], statistic, what: str, seed: int) -> Estimate:
    """A statistic of (x, y) pairs with its bootstrap interval, the pairs resampled together (BCa); the
    interval is nan below PAIRED_MIN pairs or when either side has no spread."""
    from scipy.stats import bootstrap

    u, v = _paired_finite(x, y)
    value = float(statistic(u, v)) if len(u) >= 3 else math.nan
    if len(u) < PAIRED_MIN or np.all(u == u[0]) or np.all(v == v[0]):
        return Estimate(value, math.nan, math.nan, len(u), what)
    res = bootstrap((u, v), statistic, paired=True, vectorized=False, confidence_level=CONFIDENCE,
                    n_resamples=RESAMPLES, method="BCa", random_state=np.random.default_rng(seed))  # fmt: skip
    low, high = res.confidence_interval
    return Estimate(value, float(low), float(high), len(u), what)


def _rho(u: np.ndarray, v: np.ndarray) -> float:
    from scipy.stats import spearmanr

    if np.all(u == u[0]) or np.all(v == v[0]):  # a resample without spread: no correlation to speak of
        return math.nan
    return float(spearmanr(u, v).statistic)


def _slope(u: np.ndarray, v: np.ndarray) -> float:
    du = u - u.mean()
    spread = float(du @ du)
    return float(du @ (v - v.mean())) / spread if spread > 0 else math.nan


def spearman_ci(x: Sequence[float], y: Sequence[float], seed: int = 0) -> Estimate:
    """Spearman's rho of y with x, with a bootstrap interval over the (x, y) pairs."""
    return _paired_bootstrap(x, y, _rho, "Spearman's rho", seed)


def slope_ci(x: Sequence[float], y: Sequence[float], seed: int = 0) -> Estimate:
    """The least-squares slope of y on x, with a bootstrap interval over the (x, y) pairs."""
    return _paired_bootstrap(x, y, _slope, "slope", seed)


def binomial(successes: int, n: int, null: float = 0.5) -> Comparison:
    """One group's k of n against a share `null` (e.g. one of two options preferred): the exact binomial
    test.  Effect: the observed share minus `null`."""
    from scipy.stats import binomtest

    if n == 0:
        return Comparison("binomial", math.nan, math.nan, math.nan, "share minus null", 0)
    res = binomtest(successes, n, null)
    return Comparison(f"binomial vs {null:g}", float(successes), float(res.pvalue), successes / n - null,
                      "share minus null", n)  # fmt: skip
