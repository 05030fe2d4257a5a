"""Resamplers: unbiased offspring counts, variance no larger than multinomial, valid indices."""

import numpy as np
import pytest

from replication.smc.resampling import RESAMPLERS, multinomial

SCHEMES = sorted(RESAMPLERS)
DRAWS = 20_000


def offspring_counts(scheme, weights, draws=DRAWS, seed=0):
    rng = np.random.default_rng(seed)
    n = len(weights)
    return np.array([np.bincount(RESAMPLERS[scheme](weights, rng), minlength=n) for _ in range(draws)])


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize(
    "weights",
    [
        np.array([0.35, 0.35, 0.30]),
        np.array([0.5, 0.25, 0.125, 0.0625, 0.0625]),
        np.random.default_rng(7).dirichlet(np.ones(10) * 0.5),
    ],
    ids=["0.35-0.35-0.30", "dyadic", "dirichlet"],
)
def test_expected_offspring_is_n_times_weight(scheme, weights):
    """E[copies of i] = N w_i, checked to 5 standard errors of the Monte Carlo mean."""
    if len(weights) == 3:
        # the issue's case: N = 10 particles, three of them carrying all the weight
        weights = np.concatenate([weights, np.zeros(7)])
    n = len(weights)
    counts = offspring_counts(scheme, weights)
    expected = n * weights
    standard_error = np.sqrt(np.maximum(counts.var(axis=0), 1e-12) / DRAWS)
    assert np.all(np.abs(counts.mean(axis=0) - expected) <= 5 * standard_error + 1e-12), (
        counts.mean(axis=0),
        expected,
    )


def test_issue_example_exact_means():
    """Weights (0.35, 0.35, 0.30) over N = 10 must give mean counts 3.5, 3.5, 3.0 for residual resampling."""
    weights = np.array([0.35, 0.35, 0.30] + [0.0] * 7)
    counts = offspring_counts("residual", weights)
    np.testing.assert_allclose(counts.mean(axis=0)[:3], [3.5, 3.5, 3.0], atol=0.03)
    # particle 3 gets exactly floor(3.0) = 3 copies every time: the residual of a whole number is zero
    assert np.all(counts[:, 2] == 3)


@pytest.mark.parametrize("scheme", ["systematic", "stratified", "residual"])
def test_variance_not_larger_than_multinomial(scheme):
    weights = np.random.default_rng(3).dirichlet(np.ones(20))
    n = len(weights)
    multinomial_variance = n * weights * (1 - weights)  # exact, per particle
    counts = offspring_counts(scheme, weights)
    # 10% slack covers the Monte Carlo error of a variance estimated from 20,000 draws
    assert np.all(counts.var(axis=0) <= 1.1 * multinomial_variance + 1e-9)
    assert counts.var(axis=0).sum() < 0.7 * multinomial_variance.sum()


def test_multinomial_variance_matches_theory():
    weights = np.random.default_rng(4).dirichlet(np.ones(8))
    counts = offspring_counts("multinomial", weights)
    np.testing.assert_allclose(counts.var(axis=0), 8 * weights * (1 - weights), rtol=0.1)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_output_range_dtype_and_size(scheme):
    rng = np.random.default_rng(1)
    for n in (1, 2, 17, 1000):
        weights = rng.dirichlet(np.ones(n))
        indices = RESAMPLERS[scheme](weights, rng)
        assert indices.dtype == np.int64
        assert indices.shape == (n,)
        assert indices.min() >= 0 and indices.max() < n


@pytest.mark.parametrize("scheme", SCHEMES)
def test_zero_weight_particles_are_never_chosen(scheme):
    rng = np.random.default_rng(2)
    weights = np.zeros(50)
    live = [0, 7, 8, 49]  # includes the first and the last particle, next to zero-weight ones
    weights[live] = [0.1, 0.2, 0.3, 0.4]
    for _ in range(5000):
        assert set(np.unique(RESAMPLERS[scheme](weights, rng))) <= set(live)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_a_single_live_particle_takes_every_slot(scheme):
    weights = np.zeros(10)
    weights[4] = 1.0
    assert np.all(RESAMPLERS[scheme](weights, np.random.default_rng(0)) == 4)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_same_generator_state_same_indices(scheme):
    weights = np.random.default_rng(5).dirichlet(np.ones(30))
    first = RESAMPLERS[scheme](weights, np.random.default_rng(11))
    second = RESAMPLERS[scheme](weights, np.random.default_rng(11))
    np.testing.assert_array_equal(first, second)


def test_multinomial_is_not_a_disguised_systematic():
    """Two particles of weight 1/2: systematic always gives one copy each, multinomial often does not."""
    weights = np.array([0.5, 0.5])
    counts = offspring_counts("multinomial", weights, draws=2000)
    assert (counts[:, 0] != 1).mean() > 0.4
    assert np.all(offspring_counts("systematic", weights, draws=200)[:, 0] == 1)
    assert multinomial is RESAMPLERS["multinomial"]
