"""The original's own uncertainty: the rule for the paper's run count, and the size test that treats the
paper's number as a mean of that many runs (replication.evidence.original, comparisons.size_test)."""

import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from conftest import typed

from replication.evidence.checks import Result

from replication.evidence.claim_tests import ClaimTest
from replication.evidence.comparisons import Effect, order_test
from replication.evidence.original import PaperRuns, fewest_runs, paper_runs, runs_behind
from replication.evidence.settings import INFERENCE
from replication.evidence.verdict import Outcome

SCALE = INFERENCE.alpha / INFERENCE.size_alpha  # the size test's p-value is said on the 5 % scale


def test_a_stated_count_is_taken_as_stated():
    found = paper_runs(50, stated=100, rates=["95", "55"])
    assert found == PaperRuns(100, True, "100 runs, stated")


def test_unstated_rates_give_the_fewest_runs_that_print_them():
    # 95 % and 55 %: 19 and 11 of 20; no fewer runs give both (19 gives 94.7 %, but no k / 19 rounds to 55)
    assert fewest_runs(["95", "55"]) == 20
    found = paper_runs(50, rates=["95", "55"])
    assert (found.n, found.stated) == (20, False) and found.why == "20 runs, not stated: the fewest that give 95 and 55"
    assert fewest_runs(["50"]) == 2 and fewest_runs(["33.3"]) == 3 and fewest_runs(["0.5"], high=1.0) == 2
    assert fewest_runs(["92.3", "77.3", "39.3"]) == next(  # by brute force over k / n rounded to one decimal
        n for n in range(1, 1000) if all(any(round(100 * k / n, 1) == float(r) for k in range(n + 1))
                                         for r in ("92.3", "77.3", "39.3")))


def test_otherwise_the_paper_is_taken_to_have_run_as_often_as_we_did():
    assert paper_runs(50) == PaperRuns(50, False, "runs not stated: taken as ours, 50")
    # a rate no count up to 1000 gives (12.3456 %: 10 / 81 is 12.34568) is no rate of runs
    assert fewest_runs(["12.3456"]) is None and paper_runs(7, rates=["12.3456"]).why.endswith("taken as ours, 7")


def test_only_a_yes_no_metrics_numbers_are_read_as_rates_of_runs():
    # fusion_pf's Table 1: 95 % and 55 % of runs tracked to the end (in %); ism_pf's shares of frames are no
    # rates of runs, nor is an RMSE
    assert runs_behind(50, None, ["55", "95"], "tracked_to_end[cle<=20]", 100).n == 20
    assert runs_behind(50, None, ["55", "95"], "correct_frames[iou>=0.5]", 100).n == 50
    assert runs_behind(100, None, ["4.177", "1.885"], "rmse").why == "runs not stated: taken as ours, 100"
    assert runs_behind(50, 100, ["92.3"], "correct_frames[iou>=0.5]", 100).stated


def _runs(n):
    rng = np.random.default_rng(n)
    shared = rng.normal(5.0, 1.0, n)
    worse = shared + rng.normal(0.0, 0.3, n)
    better = shared - 0.4 + rng.normal(0.0, 0.3, n)  # lower is better: better by about 0.4
    return better, worse


def test_a_difference_is_a_welch_type_t_against_the_papers_two_unpaired_means():
    better, worse = _runs(12)
    paper = Effect(3.0, 3.6, PaperRuns(10, True, "10 runs, stated"))  # the paper's gain (lower is better): 0.6
    found = order_test(better, worse, lower_is_better=True, paper=paper)
    gain = worse - better
    se = math.sqrt(gain.var(ddof=1) / 12 + (better.var(ddof=1) + worse.var(ddof=1)) / 10)
    t = (gain.mean() - 0.6) / se
    assert found.p_against == pytest.approx(min(1.0, stats.t.cdf(t, 11) * SCALE))
    assert found.size.high == pytest.approx(gain.mean() + stats.t.ppf(1 - INFERENCE.size_alpha, 11) * se)
    assert found.p_for == pytest.approx(stats.ttest_1samp(gain, 0.0, alternative="greater").pvalue)
    # the paper's number taken as exact is the old test: Student's t of our gain against it
    exact = order_test(better, worse, True, paper=Effect(3.0, 3.6, PaperRuns(math.inf, False, "exact")))
    old = stats.ttest_1samp(gain, 0.6, alternative="less").pvalue
    assert exact.p_against == pytest.approx(min(1.0, old * SCALE))
    assert exact.p_against < found.p_against  # the paper's own noise: weaker evidence that ours falls short


def test_a_ratio_carries_our_coefficients_of_variation_to_the_papers_means():
    better, worse = _runs(15)
    paper = Effect(2.0, 5.0, PaperRuns(20, True, "20 runs, stated"), "ratio")  # the paper's ratio 0.4
    found = order_test(better, worse, lower_is_better=True, paper=paper)
    short = 0.4 * worse - better
    ours = better.mean() / worse.mean()
    pooled = (15 * ours + 20 * 0.4) / 35  # the ratio both share under the null
    cv2 = better.var(ddof=1) / better.mean() ** 2 + worse.var(ddof=1) / worse.mean() ** 2
    se = math.sqrt(short.var(ddof=1) / 15 + (pooled * worse.mean()) ** 2 * cv2 / 20)
    assert found.p_against == pytest.approx(min(1.0, stats.t.cdf(short.mean() / se, 14) * SCALE))
    assert found.bound is found.gain  # a ratio's interval is not in the gain's units: the direction's shown


def test_yes_no_outcomes_against_the_papers_two_rates_at_its_run_count():
    better = np.r_[np.ones(12), np.zeros(8)]
    worse = np.r_[np.ones(6), np.zeros(10), np.ones(2), np.zeros(2)]  # 6 won by better alone, 2 by worse alone
    paper = Effect(0.95, 0.55, PaperRuns(20, False, "20 runs, not stated"))
    found = order_test(better, worse, lower_is_better=False, binary=True, paper=paper)
    ours, pooled = (6 - 2) / 20, (20 * 0.2 + 20 * 0.4) / 40  # the gaps: ours 0.2, pooled with the paper's 0.3
    variance = (8 / 20 - pooled ** 2) / 20 + (0.9 * 0.1 + 0.6 * 0.4) / 20  # the rates moved to 0.3 apart
    t = (ours - 0.4) / math.sqrt(variance)
    assert found.p_against == pytest.approx(min(1.0, stats.t.cdf(t, 19) * SCALE))
    assert found.p_for == pytest.approx(stats.binomtest(6, 8, 0.5, alternative="greater").pvalue)  # McNemar


def test_runs_that_all_sit_at_one_bound_are_tested_against_nothing():
    found = order_test(np.zeros(50), np.zeros(50), False, binary=True,
                       paper=Effect(0.95, 0.55, PaperRuns(20, False, "")))
    assert found.tied and np.isnan(found.p_for) and np.isnan(found.p_against)
    one_left = np.r_[np.zeros(49), 1.0]
    assert not order_test(one_left, np.zeros(50), False, binary=True).tied


def test_the_arrays_design_holds_with_papers_drawn_per_experiment():
    rng = np.random.default_rng(3)
    better, worse = rng.normal(0.0, 1.0, (4, 10)), rng.normal(1.0, 1.0, (4, 10))
    gains = np.array([1.0, 0.5, -0.2, 2.0])  # the third paper's numbers do not favour the claim: no size
    batch = order_test(better, worse, True, paper=Effect(np.zeros(4), gains, PaperRuns(10, True, "")))
    for i, g in enumerate(gains):
        one = order_test(better[i], worse[i], True, paper=Effect(0.0, float(g), PaperRuns(10, True, "")))
        assert batch.p_against[i] == pytest.approx(float(one.p_against))
    assert batch.p_against[2] == pytest.approx(float(order_test(better[2], worse[2], True).p_against))


PUBLISHED = pd.DataFrame({"paper": "p", "table": "1", "experiment": "", "method": ["A", "B"], "metric": "rmse",
                          "condition": "N=1", "value": ["1.6", "4.2"], "unit": "", "note": "",
                          "number": [1.6, 4.2]})


def _check(table: dict, gap: float, runs: int = 20):
    """The check of 'A beats B' (RMSE) against the paper's 1.6 and 4.2 in a table ``table``, on ``runs`` runs
    in which B is ``gap`` worse; and the runs."""
    rng = np.random.default_rng(1)
    base = rng.normal(5.0, 1.0, runs)
    better, worse = base + 0.1 * rng.standard_normal(runs), base + gap + 0.1 * rng.standard_normal(runs)
    records = typed(pd.DataFrame([{"method": m, "condition": "N=1", "data_condition": "", "repetition": r,
                                   "rmse": values[r]} for m, values in (("A", better), ("B", worse))
                                  for r in range(runs)]))
    experiment = {"paper": "p", "methods": {"A": {}, "B": {}},
                  "report": {"tables": [{"name": "t1", "paper_table": "1", "metric": "rmse", **table}]}}
    spec = {"test": "order", "metric": "rmse", "order": ["A", "B"], "size": {"table": "t1"}}
    return ClaimTest.of(spec, experiment, PUBLISHED).checks(records, {})[0], better, worse


def test_each_size_check_says_the_runs_it_took_behind_the_papers_numbers():
    stated = _check({"paper_runs": 10}, gap=2.6)[0]
    assert stated.verdict.outcome is Outcome.REPRODUCED and "(1.6 - 4.2; 10 runs, stated)" in stated.verdict.why
    assumed = _check({"paper_runs": 100, "paper_runs_stated": False}, gap=1.0)[0]
    assert assumed.verdict.outcome is Outcome.NOT_REPRODUCED
    assert "runs not stated: taken as ours, 20" in assumed.verdict.why


def test_a_users_quoted_numbers_carry_the_runs_it_gives():
    rng = np.random.default_rng(4)
    records = typed(pd.DataFrame([{"method": m, "condition": "N=1", "data_condition": "", "repetition": r,
                                   "rmse": 4.0 - 2.5 * (m == "A") + rng.normal(0.0, 0.3)}
                                  for m in ("A", "B") for r in range(20)]))
    spec = {"test": "order", "metric": "rmse", "order": ["A", "B"], "size": {"quoted": {"A": 1.6, "B": 4.2}}}
    for size, said in (({"runs": 30}, "(1.6 - 4.2; 30 runs, stated)"), ({}, "taken as ours, 20")):
        check = ClaimTest.of({**spec, "size": {**spec["size"], **size}}, {"methods": {}}).checks(records, {})[0]
        assert said in check.verdict.why and check.verdict.outcome is Outcome.REPRODUCED  # ours 2.5, theirs 2.6


def test_a_shown_difference_of_rates_stays_within_100_points():
    # every run won by A alone: ours +100 pp, whose bound with the paper's noise would pass 100
    metric = "tracked_to_end[cle<=20]"
    records = typed(pd.DataFrame([{"method": m, "condition": "N=1", "data_condition": "", "repetition": r,
                                   metric: float(m == "A")} for m in ("A", "B") for r in range(100)]))
    spec = {"test": "order", "metric": metric, "order": ["A", "B"], "scale": 100,
            "size": {"quoted": {"A": 86.4, "B": 14.7}, "runs": 100}}
    check = ClaimTest.of(spec, {"methods": {}}).checks(records, {})[0]
    assert check.estimate.value == 100.0 and check.estimate.high == 100.0 and check.estimate.low > 90.0
    assert check.verdict.outcome is Outcome.REPRODUCED


def test_the_interval_shown_is_the_one_each_test_decides_by():
    check, better, worse = _check({}, gap=1.0)  # lower is better: A - B's lower end is the size test's bound
    tested = order_test(better, worse, True, paper=Effect(1.6, 4.2, PaperRuns(20, False, "")))
    assert check.estimate.low == pytest.approx(-float(tested.size.high))  # beyond it: the paper's -2.6 rejected
    assert check.estimate.high == pytest.approx(-float(tested.gain.low))  # the direction's bound
    assert check.estimate.low > -2.6 and Result.of([check]).verdict.outcome is Outcome.NOT_REPRODUCED
    assert "with the paper's own noise (runs not stated: taken as ours, 20)" in check.estimate.method
    assert check.estimate.level == pytest.approx(1 - INFERENCE.alpha - INFERENCE.size_alpha)  # 95 % and 97 % ends
