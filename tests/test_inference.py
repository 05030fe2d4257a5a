"""The tests behind the verdicts against scipy's own, hand cases and simulation of their level."""

import math

import numpy as np
import pytest
from scipy import stats

from replication.evidence.comparisons import Effect, best_test, order_test
from replication.evidence.original import PaperRuns
from replication.evidence.inference import (
    clopper_pearson, detectable, holm, mean_test, paired_binary_test, proportion_test, sign_test,
)
from replication.evidence.settings import INFERENCE
from replication.evidence.verdict import OUTCOMES, Outcome, decide

RNG = np.random.default_rng(7)
HUNDRED = PaperRuns(100, True, "100 runs, stated")


def test_mean_test_is_scipys_one_sample_t_test_with_its_90_percent_interval():
    values = RNG.normal(1.0, 2.0, 9)
    found = mean_test(values, 0.5)
    scipy = stats.ttest_1samp(values, 0.5, alternative="greater")
    assert found.p_above == pytest.approx(scipy.pvalue)
    assert found.p_below == pytest.approx(stats.ttest_1samp(values, 0.5, alternative="less").pvalue)
    interval = stats.ttest_1samp(values, 0.5).confidence_interval(1 - 2 * INFERENCE.alpha)
    assert (found.low, found.high) == pytest.approx((interval.low, interval.high))


def test_mean_test_works_on_a_batch_and_refuses_runs_that_all_agree():
    batch = RNG.normal(size=(4, 3, 6))
    found = mean_test(batch)
    assert found.p_above.shape == (4, 3)
    assert found.p_above[2, 1] == pytest.approx(stats.ttest_1samp(batch[2, 1], 0, alternative="greater").pvalue)
    tied = mean_test([2.0, 2.0, 2.0, 2.0, 2.0])
    assert not tied.defined and math.isnan(tied.low)  # no zero-width interval, no verdict


def test_sign_test_is_the_exact_binomial_test_and_its_floor_at_5_runs_is_1_32():
    values = np.array([0.3, 1.2, 2.0, -0.1, 0.8, 0.0, 1.5])  # the tie with the reference is dropped
    found = sign_test(values)
    assert found.p_above == pytest.approx(stats.binomtest(5, 6, 0.5, alternative="greater").pvalue)
    assert sign_test([1.0, 2.0, 3.0, 4.0, 5.0]).p_above == pytest.approx(1 / 32)
    five = sign_test([5.0, 1.0, 4.0, 2.0, 3.0])
    assert (five.low, five.high) == (1.0, 5.0)  # P(min < median < max) = 30/32 >= 90%
    assert math.isnan(sign_test([1.0, 2.0, 3.0, 4.0]).low)  # 4 runs: 14/16 < 90%: no interval


def test_mcnemar_is_the_sign_test_on_the_discordant_pairs():
    ours = np.array([1, 1, 1, 0, 1, 1, 0, 1, 1, 1])
    theirs = np.array([0, 0, 1, 0, 0, 1, 1, 0, 0, 1])
    found = paired_binary_test(ours - theirs)  # 5 pairs only ours got right, 1 only theirs
    assert found.p_above == pytest.approx(stats.binomtest(5, 6, 0.5, alternative="greater").pvalue)
    assert found.low <= 0.4 <= found.high and -1 <= found.low and found.high <= 1


@pytest.mark.parametrize("k, n", [(0, 5), (3, 10), (10, 10), (37, 100)])
def test_clopper_pearson_is_scipys_exact_interval(k, n):
    scipy = stats.binomtest(k, n).proportion_ci(0.95, method="exact")
    assert clopper_pearson(k, n, 0.95) == pytest.approx((scipy.low, scipy.high))


def test_proportion_test_is_the_exact_binomial_test():
    found = proportion_test(17, 20, 0.6)
    assert found.p_above == pytest.approx(stats.binomtest(17, 20, 0.6, alternative="greater").pvalue)
    assert found.p_below == pytest.approx(stats.binomtest(17, 20, 0.6, alternative="less").pvalue)


def test_holm_by_hand():
    # sorted 0.01, 0.03, 0.04: x3, x2, x1 = 0.03, 0.06, 0.04 -> running max 0.03, 0.06, 0.06
    assert holm([0.01, 0.04, 0.03]) == pytest.approx([0.03, 0.06, 0.06])
    adjusted = holm([0.02, np.nan, 0.5])  # NaN: not in the family, which is then of two
    assert adjusted[0] == pytest.approx(0.04) and np.isnan(adjusted[1]) and adjusted[2] == pytest.approx(0.5)
    np.testing.assert_allclose(holm([[0.01, 0.2], [0.9, 0.001]]), [[0.02, 0.2], [0.9, 0.002]])


def test_detectable_effect_has_80_percent_power():
    runs = 12
    effect = detectable(1.0, runs)
    found = mean_test(RNG.normal(effect, 1.0, (20_000, runs)))
    assert np.mean(found.p_above < INFERENCE.alpha) == pytest.approx(0.8, abs=0.02)


def test_decide_by_hand():
    reproduced, not_reproduced, inconclusive, not_testable = (OUTCOMES.index(o) for o in Outcome)
    codes, reading, _ = decide([0.01, 0.02], [0.9, 0.8])
    assert list(codes) == [reproduced] * 2 and reading == reproduced  # every check holds
    codes, reading, _ = decide([0.01, 0.5], [0.9, 0.3])
    assert list(codes) == [reproduced, inconclusive] and reading == inconclusive
    codes, reading, adjusted = decide([0.9, 0.9, 0.9], [0.04, 0.5, 0.6])  # 0.04 x 3 > 5 %: Holm undoes it
    assert reading == inconclusive and adjusted[0] == pytest.approx(0.12)
    codes, reading, _ = decide([0.9, 0.01], [0.001, 0.9])
    assert list(codes) == [not_reproduced, reproduced] and reading == not_reproduced
    codes, reading, _ = decide([np.nan, 0.01], [np.nan, 0.9])  # a check that is not testable takes no part
    assert list(codes) == [not_testable, reproduced] and reading == reproduced
    assert decide([np.nan], [np.nan])[1] == not_testable


def test_order_test_orients_the_gain_and_tests_the_papers_difference():
    worse = np.array([4.2, 4.0, 4.5, 4.1, 4.3, 4.4])
    better = worse - np.array([0.1, 0.12, 0.08, 0.11, 0.09, 0.1])  # lower is better: better by about 0.1
    found = order_test(better, worse, lower_is_better=True)
    assert found.p_for < 1e-4 and found.gain.value == pytest.approx(0.1)
    sized = order_test(better, worse, lower_is_better=True, paper=Effect(1.6, 4.2, HUNDRED))  # its gain: 2.6
    assert sized.p_against < 1e-4 and sized.p_for < 1e-4  # the sign agrees, the size does not
    close = order_test(better, worse, lower_is_better=True, paper=Effect(4.1, 4.2, HUNDRED))  # its gain: 0.1
    assert close.p_against > 0.3


def test_a_ratio_is_tested_in_fiellers_linear_form():
    worse = np.array([10.0, 11.0, 9.0, 10.5, 9.5, 10.2, 9.8, 10.1])
    better = 0.5 * worse + np.array([0.1, -0.1, 0.05, -0.05, 0.0, 0.1, -0.1, 0.0])
    assert order_test(better, worse, True, paper=Effect(0.91, 2.72, HUNDRED, "ratio")).p_against < 1e-4  # 0.33
    assert order_test(better, worse, True, paper=Effect(1.0, 2.0, HUNDRED, "ratio")).p_against > 0.1  # 0.5


def test_best_test_pairs_each_competitor_over_the_sequences():
    per_sequence = np.array([[0.9, 0.5, 0.6], [0.8, 0.6, 0.7], [0.95, 0.4, 0.5], [0.7, 0.5, 0.65],
                             [0.85, 0.55, 0.6]])  # sequences x methods, higher is better
    found = best_test(per_sequence, 0, lower_is_better=False)
    assert found.p_for.shape == (2,)
    expected = stats.ttest_rel(per_sequence[:, 0], per_sequence[:, 2], alternative="greater").pvalue
    assert found.p_for[1] == pytest.approx(expected)


def test_both_tails_are_computed_directly_so_tiny_p_values_keep_their_order():
    # differences far below zero: p_below is about 1e-25 and 1e-19, which 1 - p_above would round to 0
    steep, gentle = np.linspace(-10.1, -9.9, 12), np.linspace(-10.5, -9.5, 12)
    for values in (steep, gentle):
        found = mean_test(values)
        t = values.mean() / (values.std(ddof=1) / np.sqrt(len(values)))
        assert found.p_below == pytest.approx(stats.t.cdf(t, len(values) - 1), rel=1e-9)
        assert found.p_below == pytest.approx(stats.ttest_1samp(values, 0.0, alternative="less").pvalue, rel=1e-6)
        assert 0 < found.p_below < 1e-16 and found.p_above == pytest.approx(1.0)
        assert mean_test(-values).p_above == pytest.approx(found.p_below, rel=1e-9)  # the mirror image, same tail
    assert 0 < mean_test(steep).p_below < mean_test(gentle).p_below  # still ordered, not both 0


def test_a_yes_no_sizes_tails_are_both_direct():
    def size(wins: int, runs: int, paper: Effect):  # of ``runs``, those only the claimed-better method got right
        return order_test(np.r_[np.ones(wins), np.zeros(runs - wins)], np.zeros(runs), False, binary=True,
                          paper=paper).size

    few = size(2, 100, Effect(0.95, 0.05, HUNDRED))  # against the paper's gap of 0.9
    assert 0 < few.p_below < 1e-16 and few.p_above == 1.0
    many = size(400, 400, Effect(0.6, 0.4, PaperRuns(1000, True, "")))  # the upper tail: 0 as 1 - cdf
    assert 0 < many.p_above < 1e-40 and many.p_below == 1.0
