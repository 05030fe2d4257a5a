"""Estimates over independent runs with 95% intervals that hold their level at small run counts (scipy.stats).

* a proportion of runs (a yes/no outcome): the exact Clopper-Pearson interval,
  ``scipy.stats.binomtest(k, n).proportion_ci(method="exact")``;
* a mean of a per-run metric: Student's t interval over runs, clipped to the
  metric's range (at 5 runs the BCa bootstrap covers far less than 95 %:
  ``reports/calibration.csv``);
* a mean over a fixed set of sequences of each one's mean over runs (OTB's
  per-attribute scores): the t interval with Welch-Satterthwaite degrees of freedom;
* a median (timings): the distribution-free interval between order statistics;
* a paired difference (two methods on the same data, common random numbers):
  the t interval of the mean of the per-run differences.

The decisions themselves are tests (:mod:`replication.evidence.inference`);
these intervals are what a reader sees beside them.
"""

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import stats

from replication.evidence.quantities import Quantity
from replication.evidence.settings import INFERENCE


@dataclass(frozen=True)
class Estimate:
    """A statistic over ``runs`` runs with its interval [low, high] (NaN where undefined), how it was made and
    the interval's coverage ``level`` (the inference setting's, 95 %, unless made otherwise: a check's is the
    90 % interval of the one-sided tests that decided it)."""

    value: float
    low: float
    high: float
    runs: int
    method: str
    level: float = field(default_factory=lambda: INFERENCE.level)

    @property
    def defined(self) -> bool:
        return math.isfinite(self.low) and math.isfinite(self.high)

    def contains(self, value: float) -> bool:
        return self.defined and self.low <= value <= self.high

    def widened(self, factor: float, quantity: Quantity) -> "Estimate":
        """The interval with both half-widths times ``factor`` (still inside the quantity's range)."""
        low = max(self.value - factor * (self.value - self.low), quantity.low)
        high = min(self.value + factor * (self.high - self.value), quantity.high)
        return Estimate(self.value, low, high, self.runs, f"{self.method}, widened x{factor:.2f}", self.level)

    def scaled(self, factor: float) -> "Estimate":
        return Estimate(self.value * factor, self.low * factor, self.high * factor, self.runs, self.method,
                        self.level)

    def __str__(self) -> str:
        if not math.isfinite(self.value):
            return ""
        if not self.defined:
            return f"{self.value:.4g}"
        return f"{self.value:.4g} [{self.low:.4g}, {self.high:.4g}]"


def said_level(level: float) -> str:
    """An interval's coverage as a reader sees it beside the interval: '90% CI'."""
    return f"{100 * level:g}% CI"


def _finite(values) -> np.ndarray:
    values = np.asarray(values, dtype=float)
    return values[np.isfinite(values)]


def proportion(successes: int, runs: int) -> Estimate:
    """The share of runs with an outcome and its exact Clopper-Pearson interval."""
    if runs == 0:
        return Estimate(math.nan, math.nan, math.nan, 0, "Clopper-Pearson")
    interval = stats.binomtest(int(successes), int(runs)).proportion_ci(confidence_level=INFERENCE.level,
                                                                        method="exact")
    return Estimate(successes / runs, float(interval.low), float(interval.high), int(runs), "Clopper-Pearson")


def mean(values, low: float = -math.inf, high: float = math.inf) -> Estimate:
    """The mean of ``values`` and its t interval, clipped to [low, high].  Fewer than two values, or every
    value equal: no interval (a zero-width interval would claim certainty the runs do not give)."""
    values = _finite(values)
    if len(values) == 0:
        return Estimate(math.nan, math.nan, math.nan, 0, "t")
    centre = float(values.mean())
    if len(values) < 2 or np.all(values == values[0]):
        return Estimate(centre, math.nan, math.nan, len(values), "t (every run equal)" if len(values) > 1 else "t")
    half = float(stats.t.ppf((1 + INFERENCE.level) / 2, len(values) - 1) * values.std(ddof=1) / np.sqrt(len(values)))
    return Estimate(centre, max(centre - half, low), min(centre + half, high), len(values), "t")


def stratified_mean(groups, low: float = -math.inf, high: float = math.inf, min_runs: int = 2) -> Estimate:
    """The mean over ``groups`` of each group's mean over its runs (every group weighs the same: OTB's
    mean over sequences), the groups held fixed (they are the sequences at hand, not a sample of
    sequences), with the t interval of its run-to-run noise (Welch-Satterthwaite degrees of freedom),
    clipped to [low, high].

    No interval when a group has fewer than ``min_runs`` runs; ``runs`` counts every run.
    """
    groups = [_finite(values) for values in groups]
    groups = [values for values in groups if len(values)]
    if not groups:
        return Estimate(math.nan, math.nan, math.nan, 0, "stratified t")
    centre = float(np.mean([values.mean() for values in groups]))
    runs = sum(len(values) for values in groups)
    if min(len(values) for values in groups) < max(min_runs, 2):
        return Estimate(centre, math.nan, math.nan, runs, "stratified t")
    if all(np.all(values == values[0]) for values in groups):  # as in mean: not var == 0, which rounding misses
        return Estimate(centre, math.nan, math.nan, runs, "stratified t (every run equal)")
    parts = np.array([values.var(ddof=1) / len(values) for values in groups]) / len(groups) ** 2
    df = parts.sum() ** 2 / np.sum(parts ** 2 / np.array([len(values) - 1 for values in groups]))
    half = float(stats.t.ppf((1 + INFERENCE.level) / 2, df) * np.sqrt(parts.sum()))
    return Estimate(centre, max(centre - half, low), min(centre + half, high), runs, "stratified t")


def median(values) -> Estimate:
    """The median and its distribution-free 95% interval between order statistics (binomial ranks)."""
    values = np.sort(_finite(values))
    n = len(values)
    if n == 0:
        return Estimate(math.nan, math.nan, math.nan, 0, "order statistics")
    low_rank = int(stats.binom.ppf((1 - INFERENCE.level) / 2, n, 0.5))
    high_rank = int(stats.binom.isf((1 - INFERENCE.level) / 2, n, 0.5))
    middle = float(np.median(values))
    if low_rank < 1 or high_rank >= n:  # too few runs for a 95% order-statistic interval
        return Estimate(middle, math.nan, math.nan, n, "order statistics")
    return Estimate(middle, float(values[low_rank - 1]), float(values[high_rank]), n, "order statistics")


def estimate(values, quantity: Quantity, statistic: str = "mean") -> Estimate:
    """The statistic of per-run ``values`` that fits ``quantity``: a Clopper-Pearson proportion for a yes/no
    outcome, a median between order statistics when asked, else the t interval of the mean within its range."""
    if statistic == "median":
        return median(values)
    if quantity.proportion:
        values = _finite(values)
        if not np.isin(values, (0.0, quantity.high)).all():
            raise ValueError(f"{quantity.label or 'a yes/no outcome'}: expected 0 or {quantity.high:g} per run, "
                             f"got {sorted(set(values.tolist()) - {0.0, quantity.high})[:3]}")
        return proportion(int(np.round(values.sum() / quantity.high)), len(values)).scaled(quantity.high)
    return mean(values, quantity.low, quantity.high)


def paired_difference(ours, theirs) -> Estimate:
    """Mean of the per-run differences ``ours - theirs`` (same data, common random numbers), t interval."""
    differences = np.asarray(ours, dtype=float) - np.asarray(theirs, dtype=float)
    spread = mean(differences)
    return Estimate(spread.value, spread.low, spread.high, spread.runs, f"paired {spread.method}")
