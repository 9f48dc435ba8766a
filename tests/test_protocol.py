"""The reproduction protocol's statistics against values worked by hand or by the textbook, and its
verdict rule over every case."""

from __future__ import annotations

import math

import numpy as np
import pytest

from swarm.experiments.protocol import (
    CONFIRMATION_SEEDS,
    DEVELOPMENT_SEEDS,
    NOT_REPRODUCED,
    REPRODUCED,
    REVERSED,
    SAME_DIRECTION,
    Claim,
    claims_table,
    is_confirmation,
    seeds,
    verdict,
)
from swarm.experiments.stats import (
    Comparison,
    cochran_mantel_haenszel,
    cochrans_q,
    fisher,
    kaplan_meier_median,
    logrank,
    mann_whitney,
    mcnemar,
    mean_ci,
    median_ci,
    proportion_ci,
    ratio_of_means,
    restricted_mean,
    slope_ci,
    spearman,
    spearman_ci,
    wilcoxon_paired,
)


def test_the_seed_ranges_are_disjoint_and_seeds_stay_inside_theirs():
    assert not set(DEVELOPMENT_SEEDS) & set(CONFIRMATION_SEEDS)
    assert list(seeds(3, confirm=True)) == [10_000, 10_001, 10_002] and is_confirmation(10_002)
    assert list(seeds(2, confirm=False, offset=5)) == [5, 6] and not is_confirmation(6)
    with pytest.raises(ValueError, match="do not fit"):
        seeds(10, confirm=False, offset=len(DEVELOPMENT_SEEDS) - 5)


def test_wilson_interval_matches_the_textbook():
    e = proportion_ci(8, 10)  # Wilson 95%: 0.490 to 0.943 (Newcombe 1998, Table I style check)
    assert e.value == 0.8 and e.low == pytest.approx(0.4902, abs=1e-3) and e.high == pytest.approx(0.9433, abs=1e-3)
    assert proportion_ci(0, 20).low == 0.0 and 0.0 < proportion_ci(0, 20).high < 0.2
    assert math.isnan(proportion_ci(0, 0).value)


def test_bootstrap_intervals_cover_the_true_mean_about_95_percent_of_the_time():
    rng = np.random.default_rng(3)
    hits = 0
    for k in range(120):
        e = mean_ci(rng.normal(10.0, 2.0, 40), seed=k)
        hits += e.low <= 10.0 <= e.high
    assert 0.88 <= hits / 120 <= 0.99
    same = mean_ci([1.0, 2.0, 3.0, 4.0, 10.0], seed=1)
    assert same == mean_ci([1.0, 2.0, 3.0, 4.0, 10.0], seed=1) and same.low < 4.0 < same.high  # repeatable


def test_estimates_leave_out_non_finite_values_and_say_when_n_is_too_small():
    e = median_ci([1.0, 2.0, float("nan"), 3.0, float("inf")])
    assert e.value == 2.0 and e.n == 3
    small = mean_ci([5.0, 7.0])
    assert small.value == 6.0 and math.isnan(small.low) and small.text() == "6"
    assert mean_ci([2.0, 2.0, 2.0]).text() == "2 [2, 2]"


def test_mcnemar_counts_only_the_discordant_pairs():
    a = [True] * 10 + [False] * 10
    t = mcnemar(a, [False] * 20)
    assert t.p == pytest.approx(2 * 0.5**10) and t.effect == 0.5
    assert mcnemar(a, a).p == 1.0 and mcnemar(a, a).effect == 0.0


def test_fisher_and_cmh_lean_towards_the_condition_that_succeeds_more():
    assert fisher(9, 10, 2, 10).effect == pytest.approx(0.7) and fisher(9, 10, 2, 10).p < 0.01
    t = cochran_mantel_haenszel([(9, 10, 3, 10), (8, 10, 2, 10), (7, 10, 1, 10)])
    assert t.effect > 0 and t.p < 0.001
    assert cochran_mantel_haenszel([(5, 10, 5, 10), (3, 10, 3, 10)]).p > 0.5


def test_rank_tests_give_signed_effects():
    rng = np.random.default_rng(0)
    b = rng.normal(0, 1, 30)
    paired = wilcoxon_paired(b + 1.0, b)
    assert paired.effect == 1.0 and paired.p < 0.001
    assert wilcoxon_paired(b, b).p == 1.0
    u = mann_whitney([5, 6, 7], [1, 2, 3])
    assert u.effect == 1.0 and mann_whitney([1, 2, 3], [5, 6, 7]).effect == -1.0


def test_kaplan_meier_median_of_uncensored_times_is_where_half_have_ended():
    times = np.arange(1, 11, dtype=float)
    assert kaplan_meier_median(times, [True] * 10).value == 5.0
    assert math.isnan(kaplan_meier_median(times, [True] * 4 + [False] * 6).value)  # most runs capped
    assert restricted_mean(times, [True] * 10, horizon=20.0) == pytest.approx(times.mean())


def test_logrank_sees_a_shift_and_treats_the_cap_as_censoring():
    fast, slow = np.arange(1, 21, dtype=float), np.arange(11, 31, dtype=float)
    capped = np.minimum(slow, 20.0)  # the slow group hits a cap of 20: not finished there
    t = logrank(fast, [True] * 20, capped, slow <= 20.0)
    assert t.p < 0.01 and t.effect < 0  # the fast group ends sooner
    assert logrank(fast, [True] * 20, fast, [True] * 20).p > 0.99


@pytest.mark.parametrize("expected, effect, p, answer", [
    (1, 0.3, 0.01, REPRODUCED), (1, 0.3, 0.2, SAME_DIRECTION), (1, -0.3, 0.01, REVERSED),
    (1, -0.3, 0.2, NOT_REPRODUCED), (-1, -0.3, 0.01, REPRODUCED), (-1, 0.3, 0.01, REVERSED),
    (0, 0.3, 0.2, REPRODUCED), (0, 0.3, 0.01, NOT_REPRODUCED), (1, float("nan"), 0.01, NOT_REPRODUCED),
])  # fmt: skip
def test_the_verdict_rule(expected, effect, p, answer):
    assert verdict(expected, Comparison("t", 0.0, p, effect, "e", 10)) == answer


def test_the_claims_table_prints_the_paper_beside_ours_with_the_verdict():
    t = Comparison("McNemar (exact)", 10.0, 0.0004, 0.5, "difference of proportions", 20)
    md = claims_table([Claim("more agents forage faster", "73%", "80% [70%, 88%]", t), Claim("a count", "12", "11")])
    assert "| more agents forage faster | 73% | 80% [70%, 88%] | 20 | McNemar (exact) | < 0.001 | +0.5" in md
    assert md.rstrip().endswith("| a count | 12 | 11 |  | – |  |  | – |")


def test_ratio_of_means_tests_against_its_null_and_pairs_when_told():
    rng = np.random.default_rng(1)
    b = rng.uniform(90, 110, 60)
    est, t = ratio_of_means(b * 0.5 + rng.normal(0, 1, 60), b, paired=True, null=0.5)
    assert est.low < 0.5 < est.high and t.p > 0.05
    est, t = ratio_of_means(b * 0.4, b, paired=True, null=0.5)
    assert est.value == pytest.approx(0.4) and t.p < 0.001 and t.effect == pytest.approx(-0.1)


def test_spearman_sees_a_falling_trend():
    t = spearman([12, 25, 50, 100] * 5, [0.9, 0.7, 0.5, 0.3] * 5)
    assert t.effect == pytest.approx(-1.0) and t.p < 0.001


def test_cochrans_q_with_two_conditions_is_mcnemars_chi_square_and_sees_a_paired_shift():
    a, b = [True] * 12 + [False] * 8, [True] * 4 + [False] * 16  # 8 discordant pairs, all one way
    q = cochrans_q([a, b])
    assert q.statistic == pytest.approx(8.0) and q.p == pytest.approx(0.004677735, rel=1e-6)
    assert q.effect == pytest.approx(0.4)
    assert cochrans_q([a, a, a]).p == 1.0 and cochrans_q([a, a, a]).effect == 0.0


def test_paired_bootstrap_intervals_hold_rho_and_slope_and_none_below_eight_pairs():
    rng = np.random.default_rng(3)
    x = rng.uniform(0.0, 2.0, 40)
    y = 170.0 * x + 10.0 + rng.normal(0.0, 10.0, 40)
    rho, slope = spearman_ci(x, y), slope_ci(x, y)
    assert rho.low < rho.value <= rho.high <= 1.0 and rho.value > 0.95
    assert slope.low < 170.0 < slope.high and slope.value == pytest.approx(np.polyfit(x, y, 1)[0])
    few = slope_ci(x[:5], y[:5])
    assert math.isfinite(few.value) and math.isnan(few.low) and math.isnan(few.high) and few.n == 5
