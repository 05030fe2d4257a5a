"""Every target's colour likelihood on one frame in one compiled call (the joint filters' whole-frame steps).

A joint filter scores each target's boxes against that target's reference histogram q_i (ism_pf eq 30:
:class:`~replication.vision.colour.ColourLikelihood`).  When the targets' histograms share one sample
pattern (the same bins, kernel and points: bis_pf's balls, whose grid is configured), one call reads the
boxes of every target, target after target, through the compiled kernel of
:mod:`replication.vision.histogram`, and forms each log-likelihood as
:func:`~replication.vision.likelihood.gaussian_similarity_log_likelihood` does, so every box gets the bits
the target's own likelihood gives it, without a Python call chain per target.
"""

from dataclasses import dataclass

import numpy as np
from numba import njit

from replication.vision.colour import ColourLikelihood
from replication.vision.histogram import ColourHistogram, _bhattacharyya_kernel, _largest_bin


@dataclass(frozen=True)
class ColourLikelihoods:
    """Targets' colour likelihoods sharing ``histogram``'s pattern: their sqrt(q_i) (M, B), and each one's
    2 sigma^2 and log(sqrt(2 pi) sigma)."""

    histogram: ColourHistogram
    roots: np.ndarray
    two_variance: np.ndarray
    log_norm: np.ndarray

    @classmethod
    def of(cls, likelihoods: list) -> "ColourLikelihoods | None":
        """The likelihoods as one, or None unless each is a :class:`ColourLikelihood` whose histogram has
        the first one's pattern."""
        if not likelihoods or any(type(likelihood) is not ColourLikelihood for likelihood in likelihoods):
            return None
        first = likelihoods[0].histogram
        if not all(_same_pattern(likelihood.histogram, first) for likelihood in likelihoods[1:]):
            return None
        sigmas = [likelihood.sigma for likelihood in likelihoods]
        if min(sigmas) <= 0:
            raise ValueError(f"sigma must be positive, got {min(sigmas)}")
        roots = np.sqrt(np.stack([np.asarray(likelihood.reference, dtype=float)[: first.n_bins] for likelihood in likelihoods]))
        return cls(first, roots, np.array([2.0 * sigma**2 for sigma in sigmas], dtype=float),  # as the likelihood forms them
                   np.array([np.log(np.sqrt(2.0 * np.pi) * sigma) for sigma in sigmas], dtype=float))

    def log_likelihood(self, boxes: np.ndarray, offsets: np.ndarray, bin_image: np.ndarray) -> np.ndarray:
        """log p(z | box) of every box (R, >= 4: cx, cy, w, h), rows ``offsets[i]:offsets[i + 1]`` target i's."""
        histogram = self.histogram
        image = np.ascontiguousarray(bin_image, dtype=np.uint16)
        if _largest_bin(image) >= histogram.n_bins:  # the kernel indexes its histograms by bin, unchecked
            raise ValueError(f"the bin image has bins up to {_largest_bin(image)}, this histogram {histogram.n_bins}")
        us, vs, rows, first_column, last_column, first_sample = histogram._runs
        return _log_likelihoods(
            image, np.ascontiguousarray(boxes[:, :4], dtype=float), np.asarray(offsets, dtype=np.int64), us, vs, rows,
            first_column, last_column, first_sample, histogram.weights, histogram._one_minus_v2[0],
            histogram._u2_minus_v2[0], histogram.kernel == "diagonal", histogram._total_weight,
            self.roots, self.two_variance, self.log_norm,
        )


def _same_pattern(histogram: ColourHistogram, other: ColourHistogram) -> bool:
    return (histogram.bins == other.bins and histogram.kernel == other.kernel
            and np.array_equal(histogram.points, other.points) and np.array_equal(histogram.weights, other.weights))


@njit(cache=True, error_model="numpy")
def _log_likelihoods(image, boxes, offsets, us, vs, rows, first_column, last_column, first_sample, weights,
                     one_minus_v2, u2_minus_v2, diagonal, total_weight, roots, two_variance, log_norm):
    """Target after target, rho of its boxes (the kernel) and -(1 - rho) / (2 sigma^2) - log(sqrt(2 pi)
    sigma), or -inf for a box with no sample in the image or no area (ColourLikelihood.similarity)."""
    out = np.empty(boxes.shape[0])
    for i in range(offsets.size - 1):
        first, last = offsets[i], offsets[i + 1]
        rho, inside = _bhattacharyya_kernel(image, boxes[first:last], us, vs, rows, first_column, last_column,
                                            first_sample, weights, one_minus_v2, u2_minus_v2, diagonal, total_weight,
                                            roots[i])
        for r in range(last - first):
            box = boxes[first + r]
            if inside[r] and box[2] > 0 and box[3] > 0:
                out[first + r] = -(1.0 - rho[r]) / two_variance[i] - log_norm[i]
            else:
                out[first + r] = -np.inf
    return out
