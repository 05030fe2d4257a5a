"""Resampling schemes: pure functions ``(weights, rng) -> ancestor indices``.

Each returns ``len(weights)`` indices (int64) such that the expected number of
copies of particle i is ``N * W_i`` (unbiasedness); they differ in the variance
of those counts.  See Douc, Cappé and Moulines (2005), "Comparison of
resampling schemes for particle filtering".

Every scheme finds its indices by inverse CDF in linear time, compiled, with
no binary search: systematic uniforms lie on a grid, so each particle's count of
uniforms below C_i is computed rather than searched; stratified ones come sorted,
so one merge pass over them and C; multinomial ones do not, and a guide table
(Chen and Asau, 1974: the first index of C past each of N equal slices of
[0, 1)) starts each uniform's search at most a few steps from its index.  All
compare u with the same C as ``np.searchsorted(C, u, side="right")`` and return
exactly its indices, from the same uniforms drawn in the same order.

The compiled kernels write into arrays numpy allocates: an array numba allocates
page-faults its memory in again at every call in a filter's loop (about 400
faults, 6 of a step's 31 ms at N = 10^6), where numpy's large arrays are reused.
"""

from collections.abc import Callable

import numpy as np
from numba import njit

from replication.kinds import Registry

Resampler = Callable[[np.ndarray, np.random.Generator], np.ndarray]


def cumulative_weights(weights: np.ndarray) -> np.ndarray:
    """C, the cumulative weights divided by their last entry so that C ends at exactly 1.0 and a
    zero-weight particle (a flat step of C) can never be selected."""
    return _cumulative(weights)[0]


def _cumulative(weights: np.ndarray) -> tuple[np.ndarray, bool]:
    """(C, whether C is :func:`_searchable`)."""
    weights = np.ascontiguousarray(weights, dtype=float)
    out = np.empty(weights.size)  # numpy's arrays, not numba's: see the module docstring
    return out, _fill_cumulative(weights, out)


@njit(cache=True, error_model="numpy")
def _fill_cumulative(weights, out):
    """C into ``out`` in two compiled passes: ``np.cumsum`` (a running sum in index order, so the same
    bits), then the division by its last entry, checking on the way that C is searchable."""
    if not weights.size:
        return False
    total = weights[0]
    out[0] = total
    for i in range(1, weights.size):
        total = total + weights[i]
        out[i] = total
    searchable = True
    for i in range(weights.size):
        out[i] = out[i] / total
        searchable = searchable and np.isfinite(out[i]) and (i == 0 or out[i] >= out[i - 1])
    return searchable


def inverse_cdf(weights: np.ndarray, uniforms: np.ndarray) -> np.ndarray:
    """Indices i with ``C_{i-1} <= u < C_i`` for the cumulative weights C (:func:`cumulative_weights`)."""
    cumulative, searchable = _cumulative(weights)  # checked as it is made: no second pass to check it
    return _search(cumulative, uniforms, searchable)


def inverse_cdf_rows(weights: np.ndarray, uniforms: np.ndarray) -> np.ndarray:
    """:func:`inverse_cdf` of each row of ``weights`` (M, N) with the same row of ``uniforms`` (M, K), in one
    compiled pass over the rows (:func:`_rows_inverse_cdf`): (M, K) indices, row i exactly inverse_cdf's."""
    weights, uniforms = np.ascontiguousarray(weights, dtype=float), np.ascontiguousarray(uniforms, dtype=float)
    out = np.empty(uniforms.shape, np.int64)
    searched = _rows_inverse_cdf(weights, uniforms, np.empty(weights.shape[1]),
                                 np.empty(4 * weights.shape[1] + 1, np.int64), out)
    for i in np.flatnonzero(~searched):  # C not searchable (NaN weights): numpy's search, as inverse_cdf
        out[i] = np.searchsorted(cumulative_weights(weights[i]), uniforms[i], side="right")
    return out


@njit(cache=True)
def _rows_inverse_cdf(weights, uniforms, cumulative, guide, out):
    """Row by row, C of the weights (:func:`_fill_cumulative`) and the guided search of the uniforms in it
    into ``out``; whether each row's C was searchable (a row that was not is left to numpy)."""
    searched = np.zeros(weights.shape[0], np.bool_)
    for i in range(weights.shape[0]):
        if _fill_cumulative(weights[i], cumulative):
            _guided_search(cumulative, uniforms[i], guide, out[i])
            searched[i] = True
    return searched


def search(cumulative: np.ndarray, uniforms: np.ndarray) -> np.ndarray:
    """``np.searchsorted(cumulative, uniforms, side="right")`` as int64, in O(N + K) (:func:`_guided_search`)."""
    return _search(cumulative, uniforms, bool(len(cumulative)) and _searchable(cumulative))


def _search(cumulative: np.ndarray, uniforms: np.ndarray, searchable: bool) -> np.ndarray:
    uniforms = np.ascontiguousarray(uniforms, dtype=float)
    if uniforms.ndim != 1 or not searchable:
        return np.searchsorted(cumulative, uniforms, side="right").astype(np.int64)
    return _guided_search(cumulative, uniforms, np.empty(4 * len(cumulative) + 1, np.int64),
                          np.empty(uniforms.size, np.int64))


@njit(cache=True)
def _searchable(cumulative):
    """C is finite and non-decreasing, so the guided search and ``searchsorted`` agree (a NaN
    C, from NaN weights, is left to ``searchsorted``)."""
    if not np.isfinite(cumulative[0]):
        return False
    for i in range(1, cumulative.size):
        if not (cumulative[i] >= cumulative[i - 1]) or not np.isfinite(cumulative[i]):
            return False
    return True


@njit(cache=True)
def _guided_search(cumulative, uniforms, guide, out):
    """For each u the first i with C_i > u (len(C) if none), as ``searchsorted(side="right")``.

    A guide table over 4N slices of [0, C_N) gives, for the slice u falls in, an index at or
    before u's; a forward scan while C_i <= u finds it (each index of C is passed by the
    uniforms of its own slice only: O(N + K) for K uniforms).  The slice of u is computed in
    floating point, so the start is stepped back while C_{start - 1} > u (rounding at a slice's
    edge); the answer is then exact whatever the rounding.
    """
    n, k = cumulative.size, uniforms.size
    top = cumulative[n - 1]
    slices = guide.size - 1  # 4 N: a few slices per index, so most uniforms need no step or one
    i = 0
    for b in range(slices + 1):  # guide[b]: the first i with C_i > b / slices * top
        edge = b / slices * top
        while i < n and cumulative[i] <= edge:
            i += 1
        guide[b] = i
    scale = slices / top if top > 0 else 0.0
    for j in range(k):
        u = uniforms[j]
        if not (u >= 0.0):  # negative (or NaN): below every slice
            start = 0
        elif u >= top:
            start = guide[slices]
        else:
            b = int(u * scale)
            start = guide[min(b, slices)]
        while start > 0 and cumulative[start - 1] > u:
            start -= 1
        if start < n:  # the usual single step, without a branch to mispredict
            start += cumulative[start] <= u
        while start < n and cumulative[start] <= u:
            start += 1
        out[j] = start
    return out


@njit(cache=True, error_model="numpy")
def _systematic_search(cumulative, first, counts, out):
    """The indices of the sorted uniforms u_k = (k + first) / n, k < n, as numpy makes them, without a
    merge's branch per switch between u and C.  For each particle i, m_i = #{k : u_k < C_i} is
    ceil(n C_i - first), exact unless n C_i - first lies within rounding of an integer, where it is
    settled by comparing with u_k itself; index i is then below u_k exactly when m_i <= k, so the
    indices are the running count of the m_i (``np.searchsorted(C, u, side="right")``, bit for bit)."""
    n = out.size
    counts[:] = 0  # n + 1 of them
    margin = 1e-12 * (n + 1.0)  # far above the rounding of n C_i - first and of u_k
    for i in range(cumulative.size):
        c = cumulative[i]
        x = c * n - first
        m = np.ceil(x)
        if not (margin < m - x < 1.0 - margin):  # near an integer (or outside [0, n]): compare with u_k
            m = min(max(m, 0.0), float(n))
            while m < n and (m + first) / n < c:
                m += 1.0
            while m > 0 and (m - 1.0 + first) / n >= c:
                m -= 1.0
        counts[int(min(max(m, 0.0), float(n)))] += 1
    running = 0
    for k in range(n):
        running += counts[k]
        out[k] = running
    return out


@njit(cache=True)
def _stratified_uniforms(offsets, n, out):
    """(k + U_k) / n for k < n into ``out``, as numpy's ``(np.arange(n) + U) / n``."""
    for k in range(offsets.size):
        out[k] = (k + offsets[k]) / n
    return out


@njit(cache=True)
def _is_sorted(values):
    for i in range(1, values.size):
        if not (values[i] >= values[i - 1]):
            return False
    return True


@njit(cache=True)
def _merge_sorted(cumulative, uniforms, out):
    """``searchsorted(C, u, side="right")`` for sorted u into ``out``: one merge pass."""
    i = 0
    for k in range(uniforms.size):
        while i < cumulative.size and cumulative[i] <= uniforms[k]:
            i += 1
        out[k] = i
    return out


def multinomial(weights: np.ndarray, rng: np.random.Generator, size: int | None = None) -> np.ndarray:
    """i.i.d. draws (N, or ``size``) from the categorical distribution W (Gordon et al., 1993)."""
    return inverse_cdf(weights, rng.random(len(weights) if size is None else size))


def stratified(weights: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """One uniform in each stratum ``[k/N, (k+1)/N)`` (Kitagawa, 1996)."""
    n = len(weights)
    cumulative, searchable = _cumulative(weights)
    uniforms = _stratified_uniforms(rng.random(n), n, np.empty(n))
    if not searchable or not _is_sorted(uniforms):
        return np.searchsorted(cumulative, uniforms, side="right").astype(np.int64)
    return _merge_sorted(cumulative, uniforms, np.empty(n, np.int64))


def systematic(weights: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A single uniform shared by all strata: ``u_k = (k + U) / N`` (Carpenter et al., 1999)."""
    n = len(weights)
    cumulative, searchable = _cumulative(weights)
    first = rng.random()
    if not searchable:
        return np.searchsorted(cumulative, (np.arange(n) + first) / n, side="right").astype(np.int64)
    return _systematic_search(cumulative, first, np.empty(n + 1, np.int64), np.empty(n, np.int64))


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


RESAMPLERS: Registry[Resampler] = Registry("resampling scheme", {
    "multinomial": multinomial,
    "stratified": stratified,
    "systematic": systematic,
    "residual": residual,
})
