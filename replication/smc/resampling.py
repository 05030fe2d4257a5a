"""Resampling schemes: pure functions ``(weights, rng) -> ancestor indices``.

Each returns ``len(weights)`` indices (int64) such that the expected number of
copies of particle i is ``N * W_i`` (unbiasedness); they differ in the variance
of those counts.  See Douc, Cappé and Moulines (2005), "Comparison of
resampling schemes for particle filtering".
"""

from collections.abc import Callable

import numpy as np

Resampler = Callable[[np.ndarray, np.random.Generator], np.ndarray]


def inverse_cdf(weights: np.ndarray, uniforms: np.ndarray) -> np.ndarray:
    """Indices i with ``C_{i-1} <= u < C_i`` for the cumulative weights C.

    C is divided by its last entry so that it ends at exactly 1.0 and a
    zero-weight particle (a flat step of C) can never be selected.
    """
    cumulative = np.cumsum(weights)
    cumulative /= cumulative[-1]
    return np.searchsorted(cumulative, uniforms, side="right").astype(np.int64)


def multinomial(weights: np.ndarray, rng: np.random.Generator, size: int | None = None) -> np.ndarray:
    """i.i.d. draws (N, or ``size``) from the categorical distribution W (Gordon et al., 1993)."""
    return inverse_cdf(weights, rng.random(len(weights) if size is None else size))


def stratified(weights: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """One uniform in each stratum ``[k/N, (k+1)/N)`` (Kitagawa, 1996)."""
    n = len(weights)
    return inverse_cdf(weights, (np.arange(n) + rng.random(n)) / n)


def systematic(weights: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A single uniform shared by all strata: ``u_k = (k + U) / N`` (Carpenter et al., 1999)."""
    n = len(weights)
    return inverse_cdf(weights, (np.arange(n) + rng.random()) / n)


def residual(weights: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """``floor(N W_i)`` deterministic copies, then multinomial on the residuals (Liu and Chen, 1998).

    The residual weights are ``N W_i - floor(N W_i)``, normalised over the
    ``N - sum floor(N W_i)`` draws left, so expected counts stay ``N W_i``.
    """
    n = len(weights)
    scaled = n * np.asarray(weights, dtype=float)
    copies = np.floor(scaled).astype(np.int64)
    deterministic = np.repeat(np.arange(n, dtype=np.int64), copies)
    n_left = n - int(copies.sum())
    if n_left == 0:
        return deterministic
    remainder = scaled - copies
    random_part = inverse_cdf(remainder, rng.random(n_left))
    return np.concatenate([deterministic, random_part])


RESAMPLERS: dict[str, Resampler] = {
    "multinomial": multinomial,
    "stratified": stratified,
    "systematic": systematic,
    "residual": residual,
}
