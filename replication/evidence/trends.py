"""How a metric moves across an experiment's conditions: the tests behind claims of growth ("the cost grows
linearly with the number of targets") and of a balance between two costs ("these settings keep both the
time and the error small").

Both take per-run values and return :class:`~replication.evidence.inference.Test`-like p-values in the
claimed direction, so that :func:`~replication.evidence.verdict.decide` combines them as it does every
other check.
"""

from dataclasses import dataclass

import numpy as np
from scipy import stats

from replication.evidence.inference import mean_test
from replication.evidence.settings import INFERENCE


@dataclass(frozen=True)
class Slope:
    """The least-squares slope of log(value) on log(x) over every run, with its 90 % t interval (each bound the
    one-sided 95 % bound) and the one-sided p-values of the true slope lying below (``p_below``) and above
    (``p_above``) the ``bound`` tested."""

    value: float
    low: float
    high: float
    p_below: float
    p_above: float
    points: int


def log_log_slope(x, values, bound: float) -> Slope:
    """The growth exponent b of ``values`` ~ a x^b (ordinary least squares on logs, one point per run), tested
    against ``bound``: b < bound (p_below) and b > bound (p_above), Student's t with n - 2 degrees of freedom
    (scipy.stats.linregress's standard error)."""
    x, values = np.log(np.asarray(x, dtype=float)), np.log(np.asarray(values, dtype=float))
    n = len(x)
    fit = stats.linregress(x, values)
    if n < 3 or not np.isfinite(fit.stderr) or fit.stderr == 0:
        return Slope(float(fit.slope), np.nan, np.nan, np.nan, np.nan, n)
    t = (fit.slope - bound) / fit.stderr
    half = stats.t.ppf(1 - INFERENCE.alpha, n - 2) * fit.stderr
    return Slope(float(fit.slope), float(fit.slope - half), float(fit.slope + half), float(stats.t.cdf(t, n - 2)),
                 float(stats.t.sf(t, n - 2)), n)


@dataclass(frozen=True)
class Dominance:
    """A chosen setting against one other, on two metrics where lower is better (paired by run): p_for, that
    the chosen one is better on at least one of them (the smaller one-sided p-value, Bonferroni-doubled);
    p_against, that the other is better on both (the larger of its two one-sided p-values: an
    intersection-union test)."""

    p_for: float
    p_against: float
    gains: tuple[float, float]  # the other minus the chosen, mean over runs, per metric (> 0: the chosen is better)


def dominance(chosen, other) -> Dominance:
    """``chosen`` and ``other``: runs x 2 arrays of two lower-is-better metrics on the same data (common random
    numbers), rows paired."""
    gain = np.asarray(other, dtype=float) - np.asarray(chosen, dtype=float)  # runs x metrics
    tested = mean_test(gain.T)  # per metric
    p_for = float(min(1.0, 2 * np.nanmin(tested.p_above))) if np.isfinite(tested.p_above).any() else np.nan
    p_against = float(np.max(tested.p_below)) if np.isfinite(tested.p_below).all() else np.nan
    return Dominance(p_for, p_against, (float(tested.value[0]), float(tested.value[1])))
