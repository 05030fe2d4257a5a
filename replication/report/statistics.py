"""Estimates over independent runs with 95% intervals that fit their quantity (scipy.stats throughout).

* a proportion of runs (a yes/no outcome): the Wilson score interval,
  ``scipy.stats.binomtest(k, n).proportion_ci(method="wilson")``;
* a mean of a bounded or skewed per-run metric: the BCa bootstrap over runs,
  ``scipy.stats.bootstrap(..., method="BCa")``, clipped to the metric's range;
* a mean over a fixed set of sequences of each one's mean over runs (OTB's per-attribute scores): the
  BCa bootstrap resampling the runs within each sequence;
* a median (timings): the distribution-free interval between order statistics;
* a paired difference (two methods on the same data, common random numbers):
  the BCa bootstrap of the mean of the per-run differences;
* a published rate against ours, the paper's run count known: Fisher's exact test.

Bootstrap resampling is seeded, so a report drawn twice from the same records
is the same.
"""

import math
import warnings
from dataclasses import dataclass

import numpy as np
from scipy import stats

from replication.report.quantities import Quantity

LEVEL = 0.95
RESAMPLES = 2999
SEED = 20261123  # the bootstrap's own stream: a report is a pure function of the records


@dataclass(frozen=True)
class Estimate:
    """A statistic over ``runs`` runs with its 95% interval [low, high] (NaN where undefined) and how it was made."""

    value: float
    low: float
    high: float
    runs: int
    method: str

    @property
    def defined(self) -> bool:
        return math.isfinite(self.low) and math.isfinite(self.high)

    def contains(self, value: float) -> bool:
        return self.defined and self.low <= value <= self.high

    def widened(self, factor: float, quantity: Quantity) -> "Estimate":
        """The interval with both half-widths times ``factor`` (still inside the quantity's range)."""
        low = max(self.value - factor * (self.value - self.low), quantity.low)
        high = min(self.value + factor * (self.high - self.value), quantity.high)
        return Estimate(self.value, low, high, self.runs, f"{self.method}, widened x{factor:.2f}")

    def scaled(self, factor: float) -> "Estimate":
        return Estimate(self.value * factor, self.low * factor, self.high * factor, self.runs, self.method)

    def __str__(self) -> str:
        if not math.isfinite(self.value):
            return ""
        if not self.defined:
            return f"{self.value:.4g}"
        return f"{self.value:.4g} [{self.low:.4g}, {self.high:.4g}]"


def _finite(values) -> np.ndarray:
    values = np.asarray(values, dtype=float)
    return values[np.isfinite(values)]


def proportion(successes: int, runs: int) -> Estimate:
    """The share of runs with an outcome and its Wilson score interval."""
    if runs == 0:
        return Estimate(math.nan, math.nan, math.nan, 0, "Wilson")
    interval = stats.binomtest(int(successes), int(runs)).proportion_ci(confidence_level=LEVEL, method="wilson")
    return Estimate(successes / runs, float(interval.low), float(interval.high), int(runs), "Wilson")


def bootstrap_mean(values, low: float = -math.inf, high: float = math.inf) -> Estimate:
    """The mean of ``values`` and its BCa bootstrap interval, clipped to [low, high].

    Fewer than two values: no interval.  Every value equal: the interval is the
    value itself (the bootstrap has nothing to resample).
    """
    values = _finite(values)
    if len(values) == 0:
        return Estimate(math.nan, math.nan, math.nan, 0, "bootstrap")
    mean = float(values.mean())
    if len(values) < 2:
        return Estimate(mean, math.nan, math.nan, 1, "bootstrap")
    if np.all(values == values[0]):
        return Estimate(mean, mean, mean, len(values), "bootstrap (all runs equal)")
    lo, hi = _bootstrap((values,), np.mean)
    return Estimate(mean, max(lo, low), min(hi, high), len(values), "BCa bootstrap")


def stratified_mean(groups, low: float = -math.inf, high: float = math.inf, min_runs: int = 2) -> Estimate:
    """The mean over ``groups`` of each group's mean over its runs (every group weighs the same: OTB's
    mean over sequences), with the BCa bootstrap interval that resamples the runs within each group, the
    groups held fixed (they are the sequences at hand, not a sample of sequences), clipped to [low, high].

    No interval when a group has fewer than ``min_runs`` runs; ``runs`` counts every run.
    """
    groups = [_finite(values) for values in groups]
    groups = [values for values in groups if len(values)]
    if not groups:
        return Estimate(math.nan, math.nan, math.nan, 0, "stratified bootstrap")
    mean = float(np.mean([values.mean() for values in groups]))
    runs = sum(len(values) for values in groups)
    if min(len(values) for values in groups) < max(min_runs, 2):
        return Estimate(mean, math.nan, math.nan, runs, "stratified bootstrap")
    if all(np.all(values == values[0]) for values in groups):
        return Estimate(mean, mean, mean, runs, "stratified bootstrap (all runs equal)")
    lo, hi = _bootstrap(groups, _mean_of_means)
    return Estimate(mean, max(lo, low), min(hi, high), runs, "stratified BCa bootstrap")


def _mean_of_means(*groups, axis=-1):
    return np.mean([values.mean(axis=axis) for values in groups], axis=0)


def _bootstrap(samples, statistic) -> tuple[float, float]:
    """The 95% BCa bootstrap interval of ``statistic`` over ``samples`` (each resampled on its own), or the
    percentile interval where BCa is undefined (e.g. one run differs from the rest)."""
    for method in ("BCa", "percentile"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # BCa's degenerate-data warning: handled by the fallback
            interval = stats.bootstrap(tuple(samples), statistic, method=method, confidence_level=LEVEL,
                                       n_resamples=RESAMPLES, random_state=np.random.default_rng(SEED)
                                       ).confidence_interval
        lo, hi = float(interval.low), float(interval.high)
        if math.isfinite(lo) and math.isfinite(hi):
            break
    return lo, hi


def median(values) -> Estimate:
    """The median and its distribution-free 95% interval between order statistics (binomial ranks)."""
    values = np.sort(_finite(values))
    n = len(values)
    if n == 0:
        return Estimate(math.nan, math.nan, math.nan, 0, "order statistics")
    low_rank = int(stats.binom.ppf((1 - LEVEL) / 2, n, 0.5))
    high_rank = int(stats.binom.isf((1 - LEVEL) / 2, n, 0.5))
    middle = float(np.median(values))
    if low_rank < 1 or high_rank >= n:  # too few runs for a 95% order-statistic interval
        return Estimate(middle, math.nan, math.nan, n, "order statistics")
    return Estimate(middle, float(values[low_rank - 1]), float(values[high_rank]), n, "order statistics")


def estimate(values, quantity: Quantity, statistic: str = "mean") -> Estimate:
    """The statistic of per-run ``values`` that fits ``quantity``: a Wilson proportion for a yes/no
    outcome, a median between order statistics when asked, else the bootstrap mean within its range."""
    if statistic == "median":
        return median(values)
    if quantity.proportion:
        values = _finite(values)
        if not np.isin(values, (0.0, quantity.high)).all():
            raise ValueError(f"{quantity.label or 'a yes/no outcome'}: expected 0 or {quantity.high:g} per run, "
                             f"got {sorted(set(values.tolist()) - {0.0, quantity.high})[:3]}")
        return proportion(int(np.round(values.sum() / quantity.high)), len(values)).scaled(quantity.high)
    return bootstrap_mean(values, quantity.low, quantity.high)


def paired_difference(ours, theirs) -> Estimate:
    """Mean of the per-run differences ``ours - theirs`` (same data, common random numbers), BCa interval."""
    differences = np.asarray(ours, dtype=float) - np.asarray(theirs, dtype=float)
    spread = bootstrap_mean(differences)
    return Estimate(spread.value, spread.low, spread.high, spread.runs, f"paired {spread.method}")


def rate_test(successes: int, runs: int, paper_rate: float, paper_runs: int) -> float:
    """Two-sided p-value of Fisher's exact test: our ``successes`` of ``runs`` against the paper's
    ``paper_rate`` (a proportion) of ``paper_runs``."""
    theirs = int(round(paper_rate * paper_runs))
    return float(stats.fisher_exact([[successes, runs - successes], [theirs, paper_runs - theirs]]).pvalue)
