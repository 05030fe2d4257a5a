"""The point-mass (grid) filter: the Bayes-optimal posterior mean of a scalar model.

Bucy and Senne (1971).  The posterior is carried as masses q_i on a uniform
grid x_1..x_M over [-half_width, half_width]; each step

    predictive  p(x_i | z_{1:t-1}) = sum_j q_j N(x_i; f(x_j, t), Q),
    update      q_i ∝ p(x_i | z_{1:t-1}) N(z_t; h(x_i), R).

Riemann sums on a uniform grid converge spectrally for smooth densities, so
with a spacing well under the posterior's standard deviation (which for the
UNGM never falls much below 0.5) the mean is exact to many digits; tests check
it against the Kalman filter and against a grid of half the spacing.  Masses
below ``prune * max q`` are dropped from the prediction sum (at most
``M * prune`` of the mass), which is what keeps the cost near O(M * support).
Every sum is numpy's pairwise sum and every exp and log the C library's, so the grid's means are the
same numbers on every CPU (:mod:`replication.smc.weights`); the prediction sum is compiled, each row's
exponentials summed as they are made.
"""

import math

import numpy as np
from numba import njit

from replication.libm import exp, log
from replication.models.additive import AdditiveGaussianModel
from replication.compiled import BLOCK, block_sum, half
from replication.smc.weights import moments


def point_mass_filter(
    model: AdditiveGaussianModel,
    observations: np.ndarray,
    n_points: int = 1601,
    half_width: float = 80.0,
    prune: float = 1e-12,
) -> tuple[np.ndarray, np.ndarray]:
    """Posterior means and variances of x_t given z_1..z_t on an ``n_points`` grid."""
    if n_points < 3 or half_width <= 0:
        raise ValueError("the grid needs n_points >= 3 and half_width > 0")
    grid = np.linspace(-half_width, half_width, n_points)
    if model.P0 > 0:
        support = grid
        masses = exp(-0.5 * (grid - model.x0) ** 2 / model.P0)
        masses /= masses.sum()
    else:
        support, masses = np.array([model.x0]), np.array([1.0])
    means, variances = np.empty(len(observations)), np.empty(len(observations))
    for k, z in enumerate(observations):
        t = k + 1
        keep = masses > prune * masses.max()
        log_transition = model.transition_log_density(grid[:, None], support[keep][None, :], t)
        predictive = _predictive(np.ascontiguousarray(log_transition, dtype=float), masses[keep], np.empty(n_points))
        log_post = log(predictive) + model.log_likelihood(grid, z, t)
        masses = exp(log_post - log_post.max())
        masses /= masses.sum()
        support = grid
        means[k], variances[k], _ = moments(grid, masses)
    return means, variances


@njit(cache=True, error_model="numpy")
def _predictive(log_transition, masses, out):
    """out_i = sum_j exp(log N(x_i; f(x_j), Q)) q_j for each grid point i, ``np.sum``'s order of the row."""
    scratch = np.empty(BLOCK)
    for i in range(log_transition.shape[0]):
        out[i] = 0.0 + _row_tree(log_transition[i], masses, scratch)
    return out


@njit(cache=True, error_model="numpy")
def _row_tree(log_density, masses, scratch):
    n = log_density.size
    if n > BLOCK:
        h = half(n)
        return _row_tree(log_density[:h], masses[:h], scratch) + _row_tree(log_density[h:], masses[h:], scratch)
    for j in range(n):
        scratch[j] = math.exp(log_density[j]) * masses[j]
    return block_sum(scratch[:n])
