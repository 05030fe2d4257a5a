"""Importance weights kept as log-weights, and the estimators built on them.

Every sum here is numpy's pairwise sum (:mod:`replication.compiled`), fused into the compiled pass
that makes its terms, and every exponential and logarithm is the C library's (``math.exp``, ``math.log``):
a step's weights, ESS and weighted moments are then the same numbers on every CPU, with any number of BLAS
threads (see docs/reproducibility.md, "Weights that round alike"), and a step calls no BLAS.
"""

import math

import numpy as np
from numba import njit

from replication.errors import NotFinite
from replication.libm import exp, log
from replication.compiled import BLOCK, block_sum, half


class DegenerateWeightsError(ValueError):
    """Every log-weight is -inf: the weights cannot be normalised."""


def logsumexp(a: np.ndarray, axis=None) -> np.ndarray:
    """log sum exp(a) along ``axis``, shifted by the maximum; about 2.5x faster than scipy's on the
    N x N mixtures of GPS-QMCPF and HSPF (no masking of infinities, no ``b`` weights)."""
    top = np.max(a, axis=axis, keepdims=True)
    return np.squeeze(top, axis=axis) + log(np.sum(exp(a - top), axis=axis))


def normalise(log_weights: np.ndarray, out: np.ndarray | None = None) -> tuple[np.ndarray, float]:
    """Return normalised weights ``W_i = exp(lw_i - logsumexp(lw))`` and ``logsumexp(lw)``.

    Works in the log domain throughout, so weights that would all underflow
    as raw products of likelihoods are still normalised correctly.  Raises
    :class:`DegenerateWeightsError` when every log-weight is -inf and
    :class:`~replication.errors.NotFinite` on NaN or +inf (a model's parameters
    out of range, or a bug in it; never data).  The weights go into ``out`` when it is given (an array
    of log_weights' shape, reused from step to step), else into a new array.
    """
    log_weights = np.asarray(log_weights, dtype=float)
    top = float(log_weights.max())
    if math.isnan(top) or top == math.inf:
        raise NotFinite("log-weights contain NaN or +inf")
    if top == -math.inf:
        raise DegenerateWeightsError("every log-weight is -inf")
    weights = np.empty(log_weights.shape) if out is None else out
    total = exp_sum(np.ascontiguousarray(log_weights).reshape(-1), top, weights.reshape(-1))
    weights /= total
    return weights, top + math.log(total)


@njit(cache=True, error_model="numpy")
def exp_sum(log_weights, top, out):
    """out_i = exp(lw_i - top) in one pass (``out`` may be ``log_weights``), and ``np.sum(out)``."""
    return 0.0 + _exp_tree(log_weights, top, out)


@njit(cache=True, error_model="numpy")
def _exp_tree(log_weights, top, out):
    """out_i = exp(lw_i - top) in one pass, and the pairwise tree's sum of out (``np.sum``'s order)."""
    n = log_weights.size
    if n > BLOCK:
        h = half(n)
        return _exp_tree(log_weights[:h], top, out[:h]) + _exp_tree(log_weights[h:], top, out[h:])
    for i in range(n):
        out[i] = math.exp(log_weights[i] - top)
    return block_sum(out)


def ess(weights: np.ndarray) -> float:
    """Effective sample size ``1 / sum W_i^2`` of normalised weights (Kong, Liu and Wong, 1994).

    Lies in [1, N]: N for uniform weights, 1 when one weight carries all the mass.
    """
    weights = np.ascontiguousarray(weights, dtype=float)
    return 1.0 / _sums(weights, weights[:, None], np.empty(1))


def weighted_mean(particles: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """The self-normalised importance-sampling estimate ``sum W_i x_i`` (over the first axis)."""
    return moments(particles, weights)[0]


def weighted_variance(particles: np.ndarray, weights: np.ndarray, mean: np.ndarray | None = None) -> np.ndarray:
    """Per-coordinate weighted variance ``sum W_i (x_i - mean)^2`` (``mean``: the weighted mean, if known)."""
    if mean is None:
        return moments(particles, weights)[1]
    columns, shape = _columns(particles)
    variances = np.empty(columns.shape[1])
    means = np.ravel(np.asarray(mean, dtype=float))
    _squares(np.ascontiguousarray(weights, dtype=float), columns, means, variances)
    return _shaped(variances, shape)


def moments(particles: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """(``sum W_i x_i``, ``sum W_i (x_i - mean)^2``, ESS) of the weighted particles, in two compiled passes.

    Each sum is ``np.sum`` of its terms (``np.sum(W * x)``, ``np.sum(W * (x - mean)**2)``,
    ``np.sum(W**2)``), coordinate by coordinate: numpy's pairwise order, the same on every CPU."""
    columns, shape = _columns(particles)
    weights = np.ascontiguousarray(weights, dtype=float)
    means, variances = np.empty(columns.shape[1]), np.empty(columns.shape[1])
    squares = _sums(weights, columns, means)
    _squares(weights, columns, means, variances)
    return _shaped(means, shape), _shaped(variances, shape), 1.0 / squares


def _columns(particles: np.ndarray) -> tuple[np.ndarray, tuple]:
    """The particles as an (N, d) float array (a view where it can be) and the shape of one particle."""
    particles = np.asarray(particles, dtype=float)
    return particles.reshape(len(particles), -1), particles.shape[1:]


def _shaped(values: np.ndarray, shape: tuple):
    """One particle's shape, as ``weights @ particles`` gives it: a scalar for scalar particles."""
    return values[0] if shape == () else values.reshape(shape)


@njit(cache=True, error_model="numpy")
def _sums(weights, columns, means):
    """means_j = sum W_i x_ij for each column j; returns sum W_i^2 (both ``np.sum``'s order)."""
    scratch = np.empty((2, BLOCK))
    squares = 0.0
    for j in range(columns.shape[1]):
        mean, square = _products_tree(weights, columns[:, j], scratch)
        means[j] = 0.0 + mean
        if j == 0:
            squares = 0.0 + square
    return squares


@njit(cache=True, error_model="numpy")
def _products_tree(weights, column, scratch):
    """The pairwise trees' sums of W_i x_i and of W_i^2, one pass over both arrays."""
    n = weights.size
    if n > BLOCK:
        h = half(n)
        left = _products_tree(weights[:h], column[:h], scratch)
        right = _products_tree(weights[h:], column[h:], scratch)
        return left[0] + right[0], left[1] + right[1]
    for i in range(n):
        w = weights[i]
        scratch[0, i] = w * column[i]
        scratch[1, i] = w * w
    return block_sum(scratch[0, :n]), block_sum(scratch[1, :n])


@njit(cache=True, error_model="numpy")
def _squares(weights, columns, means, variances):
    """variances_j = sum W_i (x_ij - mean_j)^2 for each column j (``np.sum``'s order)."""
    scratch = np.empty(BLOCK)
    for j in range(columns.shape[1]):
        variances[j] = 0.0 + _squares_tree(weights, columns[:, j], means[j], scratch)


@njit(cache=True, error_model="numpy")
def _squares_tree(weights, column, mean, scratch):
    n = weights.size
    if n > BLOCK:
        h = half(n)
        left = _squares_tree(weights[:h], column[:h], mean, scratch)
        return left + _squares_tree(weights[h:], column[h:], mean, scratch)
    for i in range(n):
        deviation = column[i] - mean
        scratch[i] = weights[i] * (deviation * deviation)
    return block_sum(scratch[:n])
