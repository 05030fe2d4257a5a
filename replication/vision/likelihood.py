"""Bhattacharyya similarity and the likelihood all four tracking papers use.

ism_pf eqs (30)-(32), hspf's likelihood equation, gps_qmcpf eq (17) and, with
sigma = 1 and the fused similarity, fusion_pf eq (5) all reduce to one form:

    p(z | x) = exp(-d^2 / (2 sigma^2)) / (sqrt(2 pi) sigma),  d^2 = 1 - rho,

a Gaussian in the Bhattacharyya distance d = sqrt(1 - rho).
"""

import numpy as np

from replication.compiled import elementwise


def bhattacharyya(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """rho[p, q] = sum_u sqrt(p_u q_u) over the last axis (ism_pf eq 32); 0 for an empty histogram."""
    return np.sqrt(p) @ np.sqrt(q) if q.ndim == 1 else np.sum(np.sqrt(p * q), axis=-1)


def bhattacharyya_distance(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """d = sqrt(1 - rho) (ism_pf eq 31; hspf's D[p, q])."""
    return np.sqrt(np.clip(1.0 - bhattacharyya(p, q), 0.0, None))


def gaussian_similarity_log_likelihood(similarity: np.ndarray, sigma: float, valid: np.ndarray | None = None):
    """log of exp(-(1 - s) / (2 sigma^2)) / (sqrt(2 pi) sigma) for a similarity s in [0, 1].

    ``valid`` marks particles whose box had any pixel in the image; the others
    get -inf (they cannot have produced the observation).
    """
    if sigma <= 0:
        raise ValueError(f"sigma must be positive, got {sigma}")
    return _gaussian_log(similarity, True if valid is None else valid, 2.0 * sigma**2,
                         np.log(np.sqrt(2.0 * np.pi) * sigma))


@elementwise("float64(float64, boolean, float64, float64)")
def _gaussian_log(similarity, valid, two_variance, log_norm):
    """-(1 - s) / (2 sigma^2) - log(sqrt(2 pi) sigma) where valid, else -inf: one pass, numpy's order."""
    return -(1.0 - similarity) / two_variance - log_norm if valid else -np.inf
