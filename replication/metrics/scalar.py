"""Accuracy and diagnostics of one filter run on a scalar model."""

import math

import numpy as np

from replication.metrics.means import fsum_mean
from replication.smc.loop import FilterOutput


def rmse(estimates: np.ndarray, truth: np.ndarray) -> float:
    """Root mean squared error over the time steps of one run: sqrt(mean_t (x̂_t - x_t)^2)."""
    estimates, truth = np.asarray(estimates, dtype=float), np.asarray(truth, dtype=float)
    if estimates.shape != truth.shape:
        raise ValueError(f"shape mismatch: estimates {estimates.shape} vs truth {truth.shape}")
    return math.sqrt(fsum_mean((estimates - truth) ** 2))


def filter_diagnostics(output: FilterOutput) -> dict[str, float]:
    """Mean ESS (before resampling), resampling count and rate (%), and steps with all-zero weights."""
    steps = len(output.ess)
    return {
        "mean_ess": fsum_mean(output.ess),
        "resample_count": output.resample_count,
        "resample_rate": 100.0 * output.resample_count / steps,
        "degenerate_steps": int(output.degenerate.sum()),
    }
