"""Summaries over runs: mean with a 95% Student-t interval."""

import numpy as np
import pandas as pd
from scipy import stats

LEVEL = 0.95


def mean_interval(values) -> tuple[float, float, float]:
    """Mean and the two-sided 95% t-interval of the mean; NaN bounds for fewer than two values."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if len(values) == 0:
        return np.nan, np.nan, np.nan
    mean = float(values.mean())
    if len(values) < 2:
        return mean, np.nan, np.nan
    half = float(stats.t.ppf(0.5 + LEVEL / 2, len(values) - 1) * values.std(ddof=1) / np.sqrt(len(values)))
    return mean, mean - half, mean + half


def median_interval(values) -> tuple[float, float, float]:
    """Median and a distribution-free 95% interval from order statistics (binomial ranks)."""
    values = np.sort(np.asarray(values, dtype=float)[np.isfinite(values)])
    n = len(values)
    if n == 0:
        return np.nan, np.nan, np.nan
    low_rank = int(stats.binom.ppf((1 - LEVEL) / 2, n, 0.5))
    high_rank = int(stats.binom.isf((1 - LEVEL) / 2, n, 0.5))
    if low_rank < 1 or high_rank >= n:
        return float(np.median(values)), np.nan, np.nan
    return float(np.median(values)), float(values[low_rank - 1]), float(values[high_rank])


def comparison_interval(mean: float, sd: float, runs: int, paper_runs: int | None) -> tuple[float, float]:
    """The 95% interval a published mean over ``paper_runs`` runs should fall in if both estimate the same thing.

    ``mean ± t · sd · sqrt(1/runs + 1/paper_runs)``: the published value is
    itself a Monte Carlo mean, whose spread we estimate by our own ``sd``.
    With ``paper_runs`` unknown (None) the published value is taken as exact
    and this is our own 95% interval.
    """
    if runs < 2 or not np.isfinite(sd):
        return np.nan, np.nan
    spread = 1.0 / runs + (1.0 / paper_runs if paper_runs else 0.0)
    half = float(stats.t.ppf(0.5 + LEVEL / 2, runs - 1) * sd * np.sqrt(spread))
    return mean - half, mean + half


def summarise(records: pd.DataFrame, metric: str) -> pd.DataFrame:
    """One row per (method, condition): runs, mean, 95% interval, variance and median over runs."""
    rows = []
    for (method, condition), group in records.groupby(["method", "condition"], sort=False):
        values = group[metric].astype(float)
        mean, low, high = mean_interval(values)
        rows.append(
            {
                "method": method,
                "condition": condition,
                "runs": int(values.notna().sum()),
                "mean": mean,
                "ci_low": low,
                "ci_high": high,
                "sd": float(values.std(ddof=1)) if len(values) > 1 else np.nan,
                "variance": float(values.var(ddof=1)) if len(values) > 1 else np.nan,
                "median": float(values.median()),
                "median_low": median_interval(values)[1],
                "median_high": median_interval(values)[2],
            }
        )
    return pd.DataFrame(rows)
