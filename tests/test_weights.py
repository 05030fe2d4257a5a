"""Log-weights, ESS and the weighted estimators."""

import numpy as np
import pytest

from replication.smc.weights import DegenerateWeightsError, ess, normalise, weighted_mean, weighted_variance


@pytest.mark.parametrize("n", [1, 5, 1000])
def test_ess_is_n_for_uniform_weights(n):
    assert ess(np.full(n, 1.0 / n)) == pytest.approx(n)


def test_ess_is_one_for_a_single_nonzero_weight():
    weights = np.zeros(100)
    weights[42] = 1.0
    assert ess(weights) == pytest.approx(1.0)


def test_ess_bounds_on_random_weights():
    rng = np.random.default_rng(0)
    for _ in range(200):
        n = int(rng.integers(1, 200))
        weights = rng.dirichlet(np.full(n, rng.uniform(0.05, 5)))
        assert 1.0 - 1e-9 <= ess(weights) <= n + 1e-9


def test_ess_hand_computed():
    # 1 / (0.5^2 + 0.25^2 + 0.25^2) = 1 / 0.375
    assert ess(np.array([0.5, 0.25, 0.25])) == pytest.approx(8 / 3)


def test_normalise_survives_total_underflow():
    """Log-likelihoods near -1e4 underflow to 0 as raw numbers but normalise fine in the log domain."""
    log_weights = np.array([-10_000.0, -10_001.0, -10_002.0])
    weights, log_total = normalise(log_weights)
    expected = np.exp([0.0, -1.0, -2.0])
    np.testing.assert_allclose(weights, expected / expected.sum())
    assert log_total == pytest.approx(-10_000.0 + np.log(expected.sum()))
    assert np.all(np.exp(log_weights) == 0.0)  # what raw products would have given


def test_normalise_keeps_minus_infinity_as_zero_weight():
    weights, _ = normalise(np.array([0.0, -np.inf, 0.0]))
    np.testing.assert_array_equal(weights, [0.5, 0.0, 0.5])


def test_normalise_rejects_all_minus_infinity_and_nan():
    with pytest.raises(DegenerateWeightsError):
        normalise(np.full(4, -np.inf))
    with pytest.raises(ValueError):
        normalise(np.array([0.0, np.nan]))
    with pytest.raises(ValueError):
        normalise(np.array([0.0, np.inf]))


def test_weighted_mean_and_variance_hand_computed():
    particles = np.array([[0.0, 1.0], [2.0, 3.0], [4.0, 5.0]])
    weights = np.array([0.25, 0.5, 0.25])
    np.testing.assert_allclose(weighted_mean(particles, weights), [2.0, 3.0])
    # 0.25*4 + 0.5*0 + 0.25*4 = 2 in each coordinate
    np.testing.assert_allclose(weighted_variance(particles, weights), [2.0, 2.0])
    assert weighted_mean(np.array([1.0, 3.0]), np.array([0.75, 0.25])) == pytest.approx(1.5)


def test_logsumexp_equals_scipy_along_an_axis_and_survives_underflow():
    from scipy.special import logsumexp as scipy_logsumexp

    from replication.smc.weights import logsumexp

    a = np.random.default_rng(0).normal(0, 50, (7, 9)) - 2000.0  # exp(a) underflows to 0
    for axis in (None, 0, 1):
        np.testing.assert_allclose(logsumexp(a, axis=axis), scipy_logsumexp(a, axis=axis), rtol=1e-12)
