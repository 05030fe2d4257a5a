"""Log-weights, ESS and the weighted estimators."""

import numpy as np
import pytest
from conftest import libm_exp

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


SIZES = [*range(0, 300), 1000, 4097, 8192, 8193, 100_007]


def test_pairwise_sum_is_numpys_sum_bit_for_bit():
    """The compiled tree is numpy's pairwise order (blocks of 128, eight accumulators, halves at multiples
    of 8), whose result depends on N alone: the same on every CPU, unlike BLAS's dot."""
    from replication.compiled import pairwise_sum

    rng = np.random.default_rng(1)
    for n in SIZES:
        values = rng.normal(0, 1, n) * np.exp(rng.normal(0, 10, n))  # magnitudes over many decades: order shows
        assert pairwise_sum(values) == np.sum(values), n
    assert str(pairwise_sum(np.array([-0.0, -0.0]))) == str(np.sum(np.array([-0.0, -0.0])))


@pytest.mark.parametrize("d", [None, 1, 4])
def test_weights_ess_and_moments_are_numpys_sums_of_their_terms_bit_for_bit(d):
    """W = exp(lw - max) / np.sum(exp(lw - max)), ESS = 1 / np.sum(W**2), the mean np.sum(W * x) and the
    variance np.sum(W * (x - mean)**2), coordinate by coordinate: each a fixed-order sum of its terms."""
    from replication.smc.weights import moments

    rng = np.random.default_rng(2)
    for n in [1, 7, 128, 129, 1000, 100_007]:
        log_weights = rng.normal(0, 30, n)
        shifted = libm_exp(log_weights - log_weights.max())
        weights, log_total = normalise(log_weights)
        np.testing.assert_array_equal(weights, shifted / np.sum(shifted))
        assert log_total == log_weights.max() + np.log(np.sum(shifted))
        particles = rng.normal(0, 5, n if d is None else (n, d))
        columns = particles.reshape(n, -1)
        mean, variance, effective = moments(particles, weights)
        expected_mean = [np.sum(weights * x) for x in columns.T]
        expected_variance = [np.sum(weights * (x - m) ** 2) for x, m in zip(columns.T, expected_mean)]
        np.testing.assert_array_equal(np.ravel(mean), expected_mean)
        np.testing.assert_array_equal(np.ravel(variance), expected_variance)
        assert effective == ess(weights) == 1.0 / np.sum(weights**2)
        assert np.shape(mean) == np.shape(weights @ particles)
        np.testing.assert_array_equal(weighted_mean(particles, weights), mean)
        np.testing.assert_array_equal(weighted_variance(particles, weights, mean), variance)


def test_the_c_librarys_exp_log_and_cos_elementwise():
    import math

    from replication.libm import cos, exp, log

    x = np.random.default_rng(3).uniform(-700, 700, 10_000)
    np.testing.assert_array_equal(exp(x), [math.exp(v) for v in x])
    np.testing.assert_array_equal(cos(x), [math.cos(v) for v in x])
    positive = np.abs(x) + 1e-300
    np.testing.assert_array_equal(log(positive), [math.log(v) for v in positive])
    with np.errstate(invalid="ignore"):
        np.testing.assert_array_equal(log(np.array([0.0, -1.0, np.inf, np.nan])), [-np.inf, np.nan, np.inf, np.nan])


@pytest.mark.skipif(__import__("platform").machine() not in ("x86_64", "AMD64"), reason="OpenBLAS's x86 kernels")
def test_a_filter_rounds_alike_whatever_blas_kernel_and_threads():
    """The step computes no BLAS product: with OpenBLAS forced onto its oldest x86 kernel (Prescott) and two
    threads, a bootstrap PF's means, variances, ESS and log-evidence are the same bits (before the fixed-order
    sums, ESS and means moved in their last digits, as between the record's machine and others)."""
    import os
    import subprocess
    import sys

    script = ("import numpy as np, replication as rp; from replication.models import UNGM; m = UNGM(steps=30); "
              "z = m.simulate(np.random.default_rng(0))[1]; o = rp.bootstrap(2000, 'systematic', 0.5).run(m, z, "
              "np.random.default_rng(1)); g = rp.PointMassFilter(401).run(m, z); "
              "print(np.concatenate([o.means, o.variances, o.ess, [o.log_evidence], g.means, g.variances]).tobytes().hex())")
    outputs = [subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True,
                              env={**os.environ, **extra}).stdout
               for extra in ({"OPENBLAS_NUM_THREADS": "1"}, {"OPENBLAS_CORETYPE": "Prescott", "OPENBLAS_NUM_THREADS": "2"})]
    assert outputs[0] == outputs[1]
