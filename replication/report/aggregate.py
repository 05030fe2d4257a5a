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
                "variance": float(values.var(ddof=1)) if len(values) > 1 else np.nan,
                "median": float(values.median()),
            }
        )
    return pd.DataFrame(rows)
