"""The replication criteria (replication/evidence/criteria.py) against published examples and hand cases."""

import math

import numpy as np
import pytest
from scipy import stats

from replication.evidence import criteria
from replication.evidence.comparisons import Effect, order_test
from replication.evidence.criteria import CRITERIA, CRITERION, Replication
from replication.evidence.original import PaperRuns

BIG = 10 ** 9  # runs at which Student's t is the normal


def _pair(original, original_se, replication, replication_se, runs=BIG, p_direction=0.5):
    return Replication("difference", original, original_se, replication, replication_se, p_direction, runs, runs,
                       True, 1.0)


def test_sceptical_p_matches_the_published_examples_of_held_2020_and_replicationsuccess():
    # ReplicationSuccess's tests (crsuzh/ReplicationSuccess, tests/testthat/test-pSceptical.R), nominal p_S:
    # Held (2020)'s example, two-sided, z_o^2 = 12.19, z_r^2 = 3.99, c = 1: 0.083
    assert 2 * criteria._sceptical(math.sqrt(12.19), math.sqrt(3.99), 1.0) == pytest.approx(0.083, rel=0.01)
    assert criteria._sceptical(2.33, 2.33, 1.0) == pytest.approx(0.05, rel=0.01)  # one-sided
    zo = np.arange(-4, 5, 2.0)
    published = {-4: [0.000149544079762546, 0.0236343314115514, 0.5, 0.976365668588449, 0.999850455920237],
                 -2: [0.0236343314115514, 0.0352998069509419, 0.5, 0.964700193049058, 0.976365668588449],
                 0: [0.5] * 5}
    for zr, expected in published.items():  # one-sided, c = 0.05
        np.testing.assert_allclose(criteria._sceptical(zo, float(zr), 0.05), expected, rtol=1e-9)


def test_the_golden_level_asks_an_original_just_significant_for_a_replication_at_least_as_large():
    # Held, Micheloud & Pawel (2022): with the original just significant (one-sided 2.5 %), golden success
    # is possible only where d >= 1, the bound reached as the replication grows (c large)
    zo = stats.norm.isf(0.025)
    for c in (0.5, 1.0, 2.0, 10.0):
        d = np.linspace(0.5, 3.0, 2501)
        success = criteria._sceptical(zo, d * zo * math.sqrt(c), c, criteria.GOLDEN) <= criteria.SCEPTICAL_LEVEL
        assert not success[d < 1].any()
    c = 1e6
    assert criteria._sceptical(zo, 1.01 * zo * math.sqrt(c), c, criteria.GOLDEN) <= criteria.SCEPTICAL_LEVEL
    assert criteria._sceptical(zo, 0.99 * zo * math.sqrt(c), c, criteria.GOLDEN) > criteria.SCEPTICAL_LEVEL


def test_prediction_interval_is_patil_peng_and_leeks_on_a_hand_case():
    low, high = criteria.prediction_interval(_pair(1.0, 0.3, 0.5, 0.4))
    z = stats.norm.ppf(0.975)
    assert (low, high) == pytest.approx((1 - z * 0.5, 1 + z * 0.5))  # sqrt(0.3^2 + 0.4^2) = 0.5
    few = criteria.prediction_interval(_pair(1.0, 0.3, 0.5, 0.4, runs=10))  # Student's t at 9 df: wider
    assert few[1] - few[0] == pytest.approx(2 * stats.t.ppf(0.975, 9) * 0.5)


def test_relative_effect_interval_is_fiellers():
    r = _pair(2.0, 0.5, 1.0, 0.3)
    d, low, high = criteria.relative_effect(r)
    q = stats.norm.ppf(0.975)
    assert d == 0.5
    for end in (low, high):  # each end solves (theta_r - d theta_o)^2 = q^2 (se_r^2 + d^2 se_o^2)
        assert (1.0 - end * 2.0) ** 2 == pytest.approx(q ** 2 * (0.3 ** 2 + end ** 2 * 0.5 ** 2))
    assert low < d < high
    exact = criteria.relative_effect(_pair(2.0, 1e-12, 1.0, 0.3))  # an exact original: ours / theta_o
    assert exact[1:] == pytest.approx(((1.0 - q * 0.3) / 2.0, (1.0 + q * 0.3) / 2.0))
    unbounded = criteria.relative_effect(_pair(0.5, 0.5, 1.0, 0.3))  # the original not significant
    assert np.isnan(unbounded[1]) and np.isnan(unbounded[2])


def test_small_telescope_d33_is_the_effect_the_original_detects_a_third_of_the_time():
    d33, upper = criteria.small_telescope(_pair(1.0, 0.8, 0.2, 0.1, runs=20))
    power = stats.norm.sf(stats.norm.isf(0.025) - d33 / 0.8) + stats.norm.cdf(-stats.norm.isf(0.025) - d33 / 0.8)
    assert power == pytest.approx(1 / 3, abs=1e-3)  # the other tail adds 2e-4
    assert upper == pytest.approx(0.2 + stats.t.ppf(0.95, 19) * 0.1)
    assert not CRITERION["telescope"].met(_pair(1.0, 0.8, 0.2, 0.1, runs=20))  # 0.37 < 1.22: ruled out
    assert CRITERION["telescope"].met(_pair(1.0, 0.8, 1.2, 0.1, runs=20))  # 1.37 >= 1.22


def test_fixed_effect_meta_analysis_on_a_hand_case():
    estimate, se, p = criteria.fixed_effect(_pair(2.0, 1.0, 0.0, 1.0))
    assert (estimate, se) == pytest.approx((1.0, 1 / math.sqrt(2)))
    assert p == pytest.approx(2 * stats.norm.sf(math.sqrt(2)))
    assert not CRITERION["meta"].met(_pair(2.0, 1.0, 0.0, 1.0))
    assert CRITERION["meta"].met(_pair(2.0, 1.0, 2.0, 1.0))  # 2 / 0.707 = 2.83


def test_each_criterion_on_a_replication_as_large_as_the_original_and_on_none():
    strong = _pair(1.0, 0.2, 1.0, 0.2, p_direction=stats.norm.sf(5.0))
    null = _pair(1.0, 0.3, 0.0, 0.1, p_direction=0.5)
    for criterion in CRITERIA:
        assert criterion.met(strong), criterion.key
    # 0 is outside 1 +- 1.96 * 0.3 and 1 +- 1.96 * 0.316 (the prediction interval), below d33 = 0.46 by more
    # than 1.645 * 0.1, and pooled it gives 0.1 with se 0.095
    for criterion in CRITERIA:
        assert not criterion.met(null), criterion.key


def test_effects_of_an_order_test_are_the_paper_and_ours_on_one_scale():
    rng = np.random.default_rng(1)
    worse = rng.normal(10.0, 2.0, 20)
    better = worse - 1.0 + rng.normal(0, 0.5, 20)
    runs = PaperRuns(10, True, "10 runs, stated")
    found = order_test(better, worse, lower_is_better=True, paper=Effect(8.0, 10.0, runs)).replication
    gain = worse - better
    assert found.replication == pytest.approx(gain.mean())
    assert found.replication_se == pytest.approx(gain.std(ddof=1) / math.sqrt(20))
    assert found.original == 2.0
    assert found.original_se == pytest.approx(math.sqrt((better.var(ddof=1) + worse.var(ddof=1)) / 10))
    assert found.c == pytest.approx(found.original_se ** 2 / found.replication_se ** 2)
    ratio = order_test(better, worse, lower_is_better=True, paper=Effect(8.0, 10.0, runs, "ratio")).replication
    assert ratio.original == pytest.approx(-math.log(0.8))
    assert ratio.replication == pytest.approx(-math.log(better.mean() / worse.mean()))
    assert order_test(better, worse, lower_is_better=True).replication is None  # no size quoted
    against = order_test(better, worse, lower_is_better=True, paper=Effect(10.0, 8.0, runs)).replication
    assert against is None  # the paper's own numbers do not favour the claim: no size


def _check(replication, timed=False):
    from replication.evidence.checks import Check
    from replication.evidence.verdict import Outcome, Verdict
    return Check("A - B", Verdict(Outcome.REPRODUCED, ""), timed=timed, replication=replication)


def test_a_claim_meets_a_criterion_when_each_of_its_sized_effects_does_and_says_why_none_applies():
    strong, null = _pair(1.0, 0.2, 1.0, 0.2, p_direction=1e-6), _pair(1.0, 0.3, 0.0, 0.1)
    both = criteria.assess([_check(strong), _check(null)], sized=True)
    assert both.met("significant") == 1 and both.holds("significant") is False
    assert criteria.assess([_check(strong)], sized=True).holds("significant") is True
    assert criteria.assess([_check(strong)], sized=False).why_not.endswith("the claim quotes no size")
    timed = criteria.assess([_check(strong, timed=True)], sized=True)
    assert not timed.effects and "times measured on the paper's machine" in timed.why_not
    assert criteria.assess([_check(None)], sized=True).why_not.endswith("no check of its size was testable here")
    shares = criteria.shares({"p": [both, criteria.assess([_check(strong)], sized=True),
                                    criteria.assess([], sized=False)]})
    # of the 2 claims it applies to, one meets it; of their 3 effects, two
    assert shares[0]["claims"] == 3 and shares[0]["significant"] == criteria.Share(1, 2, 2, 3)
    assert str(shares[0]["significant"]) == "1 of 2 claims (50 %); 2 of 3 effects"
    assert str(criteria.Share(0, 0, 0, 0)) == "-"
    assert shares[-1]["paper"] == "all" and shares[-1]["significant"] == criteria.Share(1, 2, 2, 3)
    median, low, high, claims = criteria.surviving([both, criteria.assess([_check(strong)], sized=True)], 999, 1)
    assert claims == 2 and median == pytest.approx(np.median([0.5, 1.0])) and low <= median <= high


def test_diff_names_a_criterion_that_moved_between_two_records():
    import pandas as pd

    from replication.report.diff import CLAIM, CLAIM_FIELDS, changes
    before = pd.DataFrame([{"claim_id": "p.claim", "verdict": "not reproduced", "criterion_sceptical": "1/2"}])
    after = before.assign(criterion_sceptical="2/2")
    assert changes(before, after, CLAIM, CLAIM_FIELDS) == [("p.claim", {"criterion_sceptical": ("1/2", "2/2")})]
