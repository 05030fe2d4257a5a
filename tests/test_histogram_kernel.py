"""The compiled colour likelihood (issue 18) against the numpy path it replaced: the same log-likelihoods
to 1e-12 and the same validity, on random frames and boxes: inside, partly and wholly outside the image,
zero-size, on half-pixel centres (cv2.remap's rounding ties), for every kernel, grid and sampled patterns."""

import numpy as np
import pytest

from replication.vision.colour import ColourLikelihood
from replication.vision.histogram import (
    KERNELS,
    ColourHistogram,
    _pairwise_program,
    _pairwise_sum,
    hsv_bin_image,
)
from replication.vision.likelihood import gaussian_similarity_log_likelihood


def random_boxes(rng, n, width, height):
    boxes = np.column_stack([
        rng.uniform(-25, width + 25, n), rng.uniform(-25, height + 25, n), rng.uniform(0, 45, n), rng.uniform(0, 45, n)
    ])
    inside = rng.random(n) < 0.5  # many wholly inside, so that groups of eight take the fast path
    boxes[inside, 0] = rng.uniform(25, width - 25, inside.sum())
    boxes[inside, 1] = rng.uniform(25, height - 25, inside.sum())
    boxes[rng.random(n) < 0.05, 2] = 0.0  # zero-size boxes
    boxes[rng.random(n) < 0.05, 3] = 0.0
    ties = rng.random(n) < 0.2  # centres on half pixels: sample coordinates land on rounding ties
    boxes[ties, :2] = np.round(boxes[ties, :2]) + 0.5
    boxes[ties, 2:] = np.round(boxes[ties, 2:])
    return boxes


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("pattern", ["grid", "sampled"])
def test_compiled_likelihood_equals_the_numpy_path(kernel, pattern):
    rng = np.random.default_rng(["grid", "sampled"].index(pattern) * 10 + KERNELS.index(kernel))
    for trial in range(12):
        height, width = (int(v) for v in rng.integers(50, 160, 2))
        frame = rng.integers(0, 256, (height, width, 3), dtype=np.uint8)
        frame[height // 4 : height // 2, width // 4 : width // 2] = rng.integers(0, 256, 3)  # a flat patch: long runs of one bin
        bins = [(8, 8, 4), (6, 6, 6), (8, 8, 2), (16, 16, 16)][trial % 4]
        if pattern == "grid":
            histogram = ColourHistogram(bins, kernel=kernel, grid=tuple(int(v) for v in rng.integers(1, 41, 2)))
        else:
            histogram = ColourHistogram(bins, kernel=kernel, samples=int(rng.integers(1, 200)), rng=rng)
        bin_image = hsv_bin_image(frame, bins)
        likelihood = ColourLikelihood.from_frame(frame, np.array([width / 2, height / 2, 20.0, 16.0]), histogram, sigma=0.1)
        boxes = random_boxes(rng, int(rng.integers(1, 400)), width, height)
        with np.errstate(invalid="ignore", divide="ignore"):  # the numpy path's 0 / 0 for zero-size diagonal boxes
            rho_numpy, valid_numpy = histogram.bhattacharyya_numpy(bin_image, boxes, likelihood.reference)
        rho, valid = histogram.bhattacharyya(bin_image, boxes, likelihood.reference)
        np.testing.assert_array_equal(valid, valid_numpy)
        np.testing.assert_array_equal(np.isnan(rho), np.isnan(rho_numpy))
        np.testing.assert_allclose(rho, rho_numpy, rtol=0, atol=1e-13, equal_nan=True)
        mask = valid_numpy & (boxes[:, 2] > 0) & (boxes[:, 3] > 0)  # ColourLikelihood.similarity's validity
        np.testing.assert_allclose(
            likelihood.log_likelihood(boxes, bin_image),
            gaussian_similarity_log_likelihood(rho_numpy, likelihood.sigma, mask),
            rtol=0, atol=1e-12,
        )


def test_a_group_of_boxes_inside_and_one_outside_agree():
    """Eight boxes inside take the fast path; a ninth, partly outside, the per-box path."""
    rng = np.random.default_rng(5)
    frame = rng.integers(0, 256, (120, 160, 3), dtype=np.uint8)
    histogram = ColourHistogram((8, 8, 4), grid=(40, 40))
    bin_image = hsv_bin_image(frame, histogram.bins)
    reference = histogram.of_boxes(bin_image, np.array([[80.0, 60.0, 40.0, 40.0]]))[0]
    boxes = np.array([[80.0 + i, 60.0 - i, 40.0, 40.0] for i in range(8)] + [[5.0, 60.0, 40.0, 40.0]])
    rho, valid = histogram.bhattacharyya(bin_image, boxes, reference)
    rho_numpy, valid_numpy = histogram.bhattacharyya_numpy(bin_image, boxes, reference)
    assert rho[0] == pytest.approx(1.0) and valid.all() and valid_numpy.all()
    np.testing.assert_allclose(rho, rho_numpy, rtol=0, atol=1e-13)


def test_the_diagonal_total_is_numpys_sum_to_the_bit():
    rng = np.random.default_rng(0)
    stack = np.empty(64)
    for n in [1, 7, 8, 9, 127, 128, 129, 255, 256, 1000, 1600, 4097]:
        weights, a, d, share = rng.random(n), rng.random(n), rng.random(n), rng.random()
        program = _pairwise_program(n)
        assert _pairwise_sum(weights, a, d, -1.0, program, stack) == weights.sum()
        assert _pairwise_sum(weights, a, d, share, program, stack) == (a - share * d).sum()
