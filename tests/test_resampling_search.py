"""The linear-time inverse CDF (issue 18) returns exactly np.searchsorted's indices from the same uniforms."""

import numpy as np
import pytest

from replication.smc.resampling import RESAMPLERS, cumulative_weights, search


def weight_sets(rng):
    for n in (1, 2, 7, 400, 2000):
        yield rng.random(n)
        yield rng.dirichlet(np.ones(n) * 0.05)  # peaked, as after a sharp likelihood
        one_hot = np.zeros(n)
        one_hot[rng.integers(n)] = 1.0
        yield one_hot
        sparse = rng.random(n) * (rng.random(n) < 0.2)  # flat steps of C: zero weights
        sparse[-1] += 1e-3
        yield sparse


def test_search_is_searchsorted():
    rng = np.random.default_rng(0)
    for weights in weight_sets(rng):
        cumulative = cumulative_weights(weights)
        uniforms = np.concatenate([rng.random(3000), [0.0, np.nextafter(1.0, 0.0)], cumulative,
                                   np.nextafter(cumulative, 0.0), np.nextafter(cumulative, 2.0)])
        np.testing.assert_array_equal(search(cumulative, uniforms), np.searchsorted(cumulative, uniforms, side="right"))
    nan = np.array([0.2, np.nan, 1.0])
    np.testing.assert_array_equal(search(nan, np.array([0.1, 0.5])), np.searchsorted(nan, np.array([0.1, 0.5]), side="right"))


@pytest.mark.parametrize("scheme", ["multinomial", "stratified", "systematic"])
def test_schemes_draw_what_they_drew_before(scheme):
    """The same stream gives the same indices as the searchsorted form before issue 18."""
    rng = np.random.default_rng(1)
    for weights in weight_sets(rng):
        weights = weights / weights.sum()
        n, seed = len(weights), int(rng.integers(2**31))
        before = np.random.default_rng(seed)
        if scheme == "multinomial":
            uniforms = before.random(n)
        elif scheme == "stratified":
            uniforms = (np.arange(n) + before.random(n)) / n
        else:
            uniforms = (np.arange(n) + before.random()) / n
        expected = np.searchsorted(cumulative_weights(weights), uniforms, side="right")
        np.testing.assert_array_equal(RESAMPLERS[scheme](weights, np.random.default_rng(seed)), expected)


def test_cumulative_weights_are_numpys_to_the_bit():
    rng = np.random.default_rng(4)
    for weights in weight_sets(rng):
        expected = np.cumsum(weights)
        expected /= expected[-1]
        assert np.array_equal(cumulative_weights(weights).view(np.int64), expected.view(np.int64))


def test_systematic_at_the_edges_is_searchsorted():
    """C_i on the grid of the uniforms (n C_i - first an integer, so the count's estimate is on an edge), the
    uniform at 0 and just below 1, huge and tiny n: the counting search still returns searchsorted's indices."""
    from replication.smc.resampling import _cumulative, _systematic_search

    rng = np.random.default_rng(5)
    for n in (1, 3, 10, 1000, 100_000):
        grid = np.zeros(n)
        grid[rng.choice(n, max(1, n // 3), replace=False)] = 1.0  # C takes values k / (n // 3): often on the u grid
        for weights in (grid, rng.random(n), rng.dirichlet(np.full(n, 0.01))):
            cumulative = _cumulative(weights)[0]
            for first in (0.0, 0.5, np.nextafter(1.0, 0.0), float(rng.random()), 1 / 3):
                expected = np.searchsorted(cumulative, (np.arange(n) + first) / n, side="right")
                found = _systematic_search(cumulative, first, np.zeros(n + 1, np.int64), np.empty(n, np.int64))
                np.testing.assert_array_equal(found, expected)


def test_rows_of_weights_are_each_inverse_cdf():
    """inverse_cdf_rows (BIS-PF's bootstrap draws for all targets at once) is inverse_cdf row by row, a row
    of NaN weights (numpy's search) and all-zero weights included."""
    from replication.smc.resampling import inverse_cdf, inverse_cdf_rows

    rng = np.random.default_rng(6)
    for m, n, k in [(1, 1, 1), (3, 10, 50), (36, 400, 4000), (5, 7, 0)]:
        weights = rng.dirichlet(np.full(n, 0.3), size=m)
        if m > 2:
            weights[1] = np.nan
            weights[2] = 0.0
        uniforms = rng.random((m, k))
        expected = np.stack([inverse_cdf(w, u) for w, u in zip(weights, uniforms)])
        np.testing.assert_array_equal(inverse_cdf_rows(weights, uniforms), expected)
