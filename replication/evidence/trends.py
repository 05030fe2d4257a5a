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
    """The least-squares slope of log(value) on log(x) over every run, with its t interval (each bound the
    one-sided bound at ``INFERENCE.growth_alpha``) and the one-sided p-values of the true slope lying below (``p_below``) and above
    (``p_above``) the ``bound`` tested; arrays over leading batch axes."""

    value: np.ndarray
    low: np.ndarray
    high: np.ndarray
    p_below: np.ndarray
    p_above: np.ndarray
    points: int


def log_log_slope(x, values, bound: float) -> Slope:
    """The growth exponent b of ``values`` ~ a x^b (ordinary least squares on logs, one point per run; last
    axis: the points, leading axes a batch), tested against ``bound``: b < bound (p_below) and b > bound
    (p_above), Student's t with n - 2 degrees of freedom and the slope's usual standard error (what
    scipy.stats.linregress gives for one set), each side at the size-corrected level ``INFERENCE.growth_alpha``
    (its p-values said on the 5 % scale, times alpha / growth_alpha, and the interval's ends its one-sided
    bounds); undefined (NaN) where the points fit a line exactly."""
    x, y = np.log(np.asarray(x, dtype=float)), np.log(np.asarray(values, dtype=float))
    n = y.shape[-1]
    dx = x - x.mean(axis=-1, keepdims=True)
    sxx = (dx ** 2).sum(axis=-1)
    slope = (dx * y).sum(axis=-1) / sxx
    residual = y - y.mean(axis=-1, keepdims=True) - slope[..., None] * dx
    se = np.sqrt((residual ** 2).sum(axis=-1) / max(n - 2, 1) / sxx)
    defined = (n > 2) & (se > 1e-12 * np.maximum(1.0, np.abs(slope)))
    with np.errstate(all="ignore"):
        t = np.where(defined, (slope - bound) / se, np.nan)
        half = stats.t.ppf(1 - INFERENCE.growth_alpha, max(n - 2, 1)) * se
    scale = INFERENCE.alpha / INFERENCE.growth_alpha
    return Slope(slope, np.where(defined, slope - half, np.nan), np.where(defined, slope + half, np.nan),
                 np.minimum(1.0, stats.t.cdf(t, max(n - 2, 1)) * scale), np.minimum(1.0, stats.t.sf(t, max(n - 2, 1)) * scale),
                 n)


@dataclass(frozen=True)
class Dominance:
    """A chosen setting against another, on two metrics where lower is better (paired by run): p_for, that
    the chosen one is better on at least one of them (the smaller one-sided p-value, Bonferroni-doubled);
    p_against, that the other is better on both (the larger of its two one-sided p-values: an
    intersection-union test); arrays over leading batch axes."""

    p_for: np.ndarray
    p_against: np.ndarray
    gains: np.ndarray  # the other minus the chosen, mean over runs, per metric (> 0: the chosen is better)


def dominance(chosen, other) -> Dominance:
    """``chosen`` and ``other``: (batch...) x runs x 2 arrays of two lower-is-better metrics on the same data
    (common random numbers), rows paired."""
    gain = np.asarray(other, dtype=float) - np.asarray(chosen, dtype=float)
    tested = mean_test(np.swapaxes(gain, -1, -2))  # per metric: (batch...) x 2
    with np.errstate(all="ignore"):
        p_for = np.minimum(1.0, 2 * np.min(np.where(np.isnan(tested.p_above), np.inf, tested.p_above), axis=-1))
    p_for = np.where(np.isfinite(p_for), p_for, np.nan)
    p_against = np.max(tested.p_below, axis=-1)  # NaN where either metric's test is undefined
    return Dominance(p_for, p_against, tested.value)
