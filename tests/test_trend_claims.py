"""The claim tests of how a metric moves across conditions (growth, a balance of two costs) and of a rank:
hand cases against scipy and against what the data were built to show."""

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from conftest import typed
from replication.evidence.checks import Result
from replication.evidence.claim_tests import ClaimTest
from replication.evidence.trends import dominance, log_log_slope
from replication.evidence.settings import INFERENCE
from replication.evidence.verdict import Outcome

EXPERIMENT = {"name": "t", "scenes": {}}


def _verdict(spec, records):
    return Result.of(ClaimTest.of(spec, EXPERIMENT).checks(records, {})).verdict


def test_the_log_log_slope_is_scipys_least_squares_on_logs_with_its_t_test():
    rng = np.random.default_rng(3)
    x = np.repeat([4.0, 9.0, 16.0, 36.0, 64.0], 3)
    y = 0.25 * x ** 1.1 * np.exp(0.05 * rng.standard_normal(len(x)))
    slope = log_log_slope(x, y, bound=1.5)
    fit = stats.linregress(np.log(x), np.log(y))
    t = (fit.slope - 1.5) / fit.stderr
    assert slope.value == pytest.approx(fit.slope)
    corrected = INFERENCE.alpha / INFERENCE.growth_alpha  # each side at the size-corrected level, said on the 5 % scale
    assert slope.p_below == pytest.approx(min(1.0, stats.t.cdf(t, len(x) - 2) * corrected))
    assert slope.p_above == pytest.approx(min(1.0, stats.t.sf(t, len(x) - 2) * corrected))
    assert slope.low < fit.slope < slope.high
    assert slope.high == pytest.approx(fit.slope + stats.t.ppf(1 - INFERENCE.growth_alpha, len(x) - 2) * fit.stderr)


def _growth_records(exponent: float) -> pd.DataFrame:
    rng = np.random.default_rng(5)
    rows = [{"method": "A", "condition": f"scene={m}", "data_condition": "", "repetition": r,
             "ms_per_frame": 0.3 * m ** exponent * np.exp(0.05 * rng.standard_normal())}
            for m in (4, 9, 16, 25, 36, 64) for r in range(3)]
    return typed(pd.DataFrame(rows))


def test_linear_growth_is_told_from_quadratic():
    spec = {"test": "growth", "method": "A", "metric": "ms_per_frame", "x": "scene", "at_most": 1.5}
    assert _verdict(spec, _growth_records(1.0)).outcome is Outcome.REPRODUCED
    assert _verdict(spec, _growth_records(2.0)).outcome is Outcome.NOT_REPRODUCED


def _sweep(time: dict, error: dict, runs: int = 10) -> pd.DataFrame:
    """Settings of one method on common data: each run shares a base error and time, plus each setting's own."""
    rng = np.random.default_rng(7)
    base = rng.normal(0.0, 1.0, (runs, 2))
    return typed(pd.DataFrame([{"method": "H", "condition": label, "data_condition": "", "repetition": r,
                                "rmse": 5 + base[r, 0] + error[label] + 0.05 * rng.standard_normal(),
                                "ms_per_step": 1 + 0.1 * base[r, 1] + time[label] + 0.01 * rng.standard_normal()}
                               for label in time for r in range(runs)]))


def test_a_balance_holds_where_no_setting_is_better_on_both_and_fails_where_one_is():
    spec = {"test": "pareto", "method": "H", "chosen": {"s": "a"}, "metrics": ["rmse", "ms_per_step"]}
    balanced = _sweep({"s=a": 0.0, "s=b": 0.5, "s=c": -0.5}, {"s=a": 0.0, "s=b": -0.5, "s=c": 0.5})  # b slower, c worse
    assert _verdict(spec, balanced).outcome is Outcome.REPRODUCED
    dominated = _sweep({"s=a": 0.0, "s=b": -0.5}, {"s=a": 0.0, "s=b": -0.5})  # b faster and more accurate
    verdict = _verdict(spec, dominated)
    assert verdict.outcome is Outcome.NOT_REPRODUCED and "s=b is better on both" in verdict.why


def test_dominance_is_an_intersection_union_test_against_and_bonferroni_for():
    rng = np.random.default_rng(11)
    chosen = rng.normal(0, 1, (12, 2))
    other = chosen + np.array([0.3, -0.4]) + 0.2 * rng.standard_normal((12, 2))
    tested = dominance(chosen, other)
    per = [stats.ttest_1samp(other[:, k] - chosen[:, k], 0.0, alternative="greater").pvalue for k in range(2)]
    against = [stats.ttest_1samp(other[:, k] - chosen[:, k], 0.0, alternative="less").pvalue for k in range(2)]
    assert tested.p_for == pytest.approx(min(1.0, 2 * min(per)))
    assert tested.p_against == pytest.approx(max(against))


def _ranked(leader_gap: float) -> pd.DataFrame:
    """Seven methods over five sequences, five runs each: the first ahead of the rest by ``leader_gap``."""
    rng = np.random.default_rng(13)
    rows = []
    for s in range(5):
        level = rng.normal(0.5, 0.1)
        for k, method in enumerate("ABCDEFG"):
            for r in range(5):
                score = level + (leader_gap if k == 0 else -0.02 * k) + 0.01 * rng.standard_normal()
                rows.append({"method": method, "condition": f"scene=s{s}", "data_condition": f"scene=s{s}",
                             "repetition": r, "precision20": score})
    return typed(pd.DataFrame(rows))


def test_a_rank_claim_reads_the_rank_set():
    spec = {"test": "rank", "method": "A", "metric": "precision20", "top": 3}
    assert _verdict(spec, _ranked(0.3)).outcome is Outcome.REPRODUCED
    assert _verdict(spec, _ranked(-0.5)).outcome is Outcome.NOT_REPRODUCED
    assert _verdict({**spec, "sequences": ["s0", "s1", "s2"]}, _ranked(0.3)).outcome is Outcome.NOT_TESTABLE


def test_the_tests_run_over_a_batch_as_over_one_set():
    """The calibration passes thousands of simulated experiments at once through the same code."""
    rng = np.random.default_rng(17)
    x = np.repeat([4.0, 9.0, 16.0, 36.0], 3)
    y = np.exp(rng.normal(0, 0.1, (4, len(x)))) * x ** 1.2
    batch = log_log_slope(x, y, 1.5)
    for k in range(4):
        one = log_log_slope(x, y[k], 1.5)
        assert batch.value[k] == pytest.approx(float(one.value)) and batch.p_below[k] == pytest.approx(float(one.p_below))
    chosen, other = rng.normal(0, 1, (4, 10, 2)), rng.normal(0.3, 1, (4, 10, 2))
    both = dominance(chosen, other)
    for k in range(4):
        assert both.p_for[k] == pytest.approx(float(dominance(chosen[k], other[k]).p_for))
        assert both.p_against[k] == pytest.approx(float(dominance(chosen[k], other[k]).p_against))
