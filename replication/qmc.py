"""Point sets on [0, 1)^s for quasi-Monte-Carlo particle filters (gps_qmcpf §1.1 and §2.1).

* the good point set (佳点集) of Hua Luogeng and Wang Yuan, gps_qmcpf §2.1;
* the Halton sequence, gps_qmcpf eqs (1)-(2), taken from :mod:`scipy.stats.qmc`;
* the Cranley-Patterson random shift that makes either a randomised QMC set;
* their discrepancy (gps_qmcpf eqs (3)-(4) define the star discrepancy; scipy
  computes the centred and L2-star discrepancies in closed form), and the
  comparison of gps_qmcpf figures 1-3 as a table.
"""

from functools import lru_cache

import numpy as np
import pandas as pd
from scipy.stats import qmc

GOOD_POINT_KINDS = ("cos", "exp")
DISCREPANCIES = ("CD", "L2-star")


def _fraction(x):
    """{x} = x - floor(x), in [0, 1) also for negative x."""
    return x - np.floor(x)


def _check_size(n: int, s: int) -> None:
    for name, value in (("n", n), ("s", s)):
        if int(value) != value or value <= 0:
            raise ValueError(f"{name} must be a positive integer, got {value}")


def _smallest_prime_at_least(m: int) -> int:
    p = max(m, 2)
    while any(p % q == 0 for q in range(2, int(p**0.5) + 1)):
        p += 1
    return p


def good_point(s: int, kind: str = "cos") -> np.ndarray:
    """The good point r in G_s, gps_qmcpf §2.1 item 5).

    ``kind="cos"``: r_i = {2 cos(2 pi i / p)}, i = 1..s, p the smallest prime with
    (p - 3)/2 >= s.  The paper prints "(p - s)/2 >= s"; we use the standard
    (p - 3)/2 of Hua and Wang (1981) (baselines.md §6, checked against public
    GPS_init.m).  The two agree for s <= 3 (p = 7 for s = 2, 11 for s = 3).
    ``kind="exp"``: r_i = {exp(i)}.
    """
    _check_size(1, s)
    i = np.arange(1, s + 1)
    if kind == "cos":
        p = _smallest_prime_at_least(2 * s + 3)
        return _fraction(2.0 * np.cos(2.0 * np.pi * i / p))
    if kind == "exp":
        return _fraction(np.exp(i.astype(float)))
    raise ValueError(f"unknown good point kind {kind!r}; choose one of {GOOD_POINT_KINDS}")


def good_point_set(n: int, s: int, kind: str = "cos") -> np.ndarray:
    """The good point set P_n(k) = ({r_1 k}, ..., {r_s k}), k = 1..n, shape (n, s) (gps_qmcpf §2.1 item 4).

    Its discrepancy, eq (4), is C(r, eps) n^(-1 + eps) for every eps > 0; the
    set is deterministic and the same for every n up to its length.
    """
    _check_size(n, s)
    k = np.arange(1, n + 1, dtype=float)
    return _fraction(np.outer(k, good_point(s, kind)))


def halton(n: int, s: int, rng: np.random.Generator | None = None, scramble: bool = False) -> np.ndarray:
    """Points k = 1..n of the s-dimensional Halton sequence, eqs (1)-(2), by :class:`scipy.stats.qmc.Halton`.

    Point k = 0 (the origin, where the inverse normal CDF is -inf) is skipped.
    ``scramble=True`` permutes the digits with ``rng``, which is then required.
    """
    _check_size(n, s)
    if scramble and rng is None:
        raise ValueError("a scrambled Halton sequence needs an rng")
    sampler = qmc.Halton(s, scramble=scramble, rng=rng)
    sampler.fast_forward(1)
    return sampler.random(n)


def random_shift(points: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Cranley-Patterson rotation (u + U) mod 1 with one U ~ U[0, 1)^s for all points.

    Each shifted point is uniform on [0, 1)^s and the set keeps its lattice
    structure: a randomised QMC set, independent between calls.
    """
    points = np.asarray(points, dtype=float)
    if points.ndim != 2:
        raise ValueError(f"points must be an (n, s) array, got shape {points.shape}")
    return (points + rng.random(points.shape[1])) % 1.0


POINT_SETS = {
    "halton": lambda n, s: halton(n, s),
    "good_cos": lambda n, s: good_point_set(n, s, "cos"),
    "good_exp": lambda n, s: good_point_set(n, s, "exp"),
}


@lru_cache(maxsize=64)
def point_set(name: str, n: int, s: int) -> np.ndarray:
    """The deterministic point set ``name`` (a key of :data:`POINT_SETS`), (n, s), cached and read-only."""
    if name not in POINT_SETS:
        raise ValueError(f"unknown point set {name!r}; choose one of {sorted(POINT_SETS)}")
    points = POINT_SETS[name](n, s)
    points.flags.writeable = False
    return points


def discrepancy(points: np.ndarray, method: str = "CD") -> float:
    """Centred ("CD") or L2-star discrepancy of points in [0, 1]^s (:func:`scipy.stats.qmc.discrepancy`)."""
    if method not in DISCREPANCIES:
        raise ValueError(f"unknown discrepancy {method!r}; choose one of {DISCREPANCIES}")
    return float(qmc.discrepancy(np.asarray(points, dtype=float), method=method))


def discrepancy_table(
    n: int = 400, dims: tuple[int, ...] = (2, 3, 5), method: str = "CD", seeds: int = 10
) -> pd.DataFrame:
    """Discrepancy of n random, Halton and good points (both kinds) in s dimensions (gps_qmcpf figs 1-3).

    The random column is the mean over ``seeds`` independent point sets.
    """
    rows = []
    for s in dims:
        rngs = (np.random.default_rng(seed) for seed in range(seeds))
        rows.append(
            {
                "s": s,
                "n": n,
                "random": float(np.mean([discrepancy(rng.random((n, s)), method) for rng in rngs])),
                "halton": discrepancy(halton(n, s), method),
                "good_cos": discrepancy(good_point_set(n, s, "cos"), method),
                "good_exp": discrepancy(good_point_set(n, s, "exp"), method),
            }
        )
    return pd.DataFrame(rows)
