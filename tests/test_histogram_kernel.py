"""The compiled colour likelihood (issue 18) against the numpy path it replaced: the same log-likelihoods
to 1e-12 and the same validity, on random frames and boxes: inside, partly and wholly outside the image,
zero-size, on half-pixel centres (cv2.remap's rounding ties), for every kernel, grid and sampled patterns."""

import numpy as np
import pytest

from replication.vision.colour import ColourLikelihood
from replication.vision.histogram import KERNELS, ColourHistogram, hsv_bin_image
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


@pytest.mark.parametrize("kernel", KERNELS)
def test_boxes_on_the_same_pixels_are_read_once_and_each_gets_the_rho_it_would_get_alone(kernel):
    """A fixed-size cloud (the ball trackers'): the kernel reads one box per distinct sample pattern
    (_same_pattern), and every box's rho and validity are those of the box read alone, to the bit, whether
    its corner lies near a half pixel, a sample's rounding edge, the image's edge or far outside; boxes it
    merges gather the same bins (the numpy path's cv2.remap)."""
    from replication.vision.histogram import _same_pattern

    rng = np.random.default_rng(KERNELS.index(kernel))
    frame = rng.integers(0, 256, (60, 80, 3), dtype=np.uint8)
    merged = 0
    for trial in range(60):
        grid = [(10, 10), (7, 5), (32, 32), (3, 9)][trial % 4]
        samples = 50 if trial % 7 == 0 else None
        histogram = ColourHistogram((8, 8, 4), kernel, grid, samples, np.random.default_rng(trial) if samples else None)
        bin_image = hsv_bin_image(frame, (8, 8, 4))
        reference = rng.dirichlet(np.ones(histogram.n_bins))
        w, h = rng.choice([20.0, 21.0, 7.5, 1.0, 0.3, rng.uniform(0.5, 40)]), rng.choice([20.0, 13.0, 2.5, rng.uniform(0.5, 40)])
        n = int(rng.choice([2, 9, 64, 400]))
        boxes = np.c_[rng.uniform(-10, 90, 2) + rng.normal(0, rng.choice([0.01, 0.3, 1.5, 5.0]), (n, 2)), np.full((n, 2), [w, h])]
        if trial % 5 == 0:  # corners on a sample's rounding edge, and within float32's rounding of it
            shifts = np.float64(histogram._runs[0][rng.integers(histogram._runs[0].size, size=n)] * (np.float32(w) / np.float32(2)))
            boxes[:, 0] = np.round(boxes[:, 0]) + 1.0 - shifts + rng.choice([0, 1e-7, -1e-7, 1e-5, 3e-8], n)
        if trial % 11 == 0:
            boxes[:, :2] *= rng.choice([1e3, 1e6, -1e4])
        rho, valid = histogram.bhattacharyya(bin_image, boxes, reference)
        alone = [histogram.bhattacharyya(bin_image, boxes[i : i + 1], reference) for i in range(n)]
        assert rho.tobytes() == np.array([r[0] for r, _ in alone]).tobytes()
        np.testing.assert_array_equal(valid, [v[0] for _, v in alone])
        source = _same_pattern(np.ascontiguousarray(boxes), *histogram._runs[:2], 80, 60)
        bins, _ = histogram.gather(bin_image, boxes)
        np.testing.assert_array_equal(bins, bins[source])  # a merged box reads its representative's pixels
        merged += int((source != np.arange(n)).sum())
    assert merged > 1000  # the clouds share pixels: the merging was exercised


def test_boxes_of_different_sizes_are_not_merged():
    from replication.vision.histogram import _same_pattern

    histogram = ColourHistogram((8, 8, 4), "epanechnikov", (10, 10))
    boxes = np.tile([40.2, 30.3, 20.0, 20.0], (5, 1))
    np.testing.assert_array_equal(_same_pattern(boxes, *histogram._runs[:2], 80, 60), [0, 0, 0, 0, 0])
    boxes[3, 2] = 20.5
    np.testing.assert_array_equal(_same_pattern(boxes, *histogram._runs[:2], 80, 60), np.arange(5))
    boxes = np.tile([40.0, 30.3, 20.0, 20.0], (5, 1))  # corners on a rounding tie: each box read alone
    np.testing.assert_array_equal(_same_pattern(boxes, *histogram._runs[:2], 80, 60), np.arange(5))


def test_the_joint_bin_image_is_lut_then_transform_for_every_colour():
    """Every one of the 2^24 BGR colours: the compiled bin image equals OpenCV's LUT of each channel's term
    followed by their sum (cv2.transform with weights 1, 1, 1), the two passes it replaced."""
    import cv2

    from replication.vision.histogram import _contributions

    codes = np.arange(1 << 24, dtype=np.uint32)
    frame = np.stack([(codes >> 16) & 255, (codes >> 8) & 255, codes & 255], -1).astype(np.uint8).reshape(4096, 4096, 3)
    for bins in [(8, 8, 4), (6, 6, 6), (16, 16, 16), (1, 1, 1), (180, 2, 2)]:
        terms = cv2.LUT(cv2.cvtColor(frame, cv2.COLOR_BGR2HSV), _contributions(bins)[:, None, :])
        expected = cv2.transform(terms, np.ones((1, 3), np.float32))
        np.testing.assert_array_equal(hsv_bin_image(frame, bins), expected)


def test_the_gaussian_likelihood_of_a_similarity_is_numpys_formula_to_the_bit():
    rng = np.random.default_rng(3)
    similarity = np.r_[rng.uniform(-0.5, 1.5, 10_000), np.nan, 0.0, 1.0, np.inf, -np.inf]
    valid = rng.random(similarity.size) < 0.8
    for sigma in (0.1, 0.2, 1.0, 1e-3, 7.0):
        with np.errstate(invalid="ignore"):
            formula = -(1.0 - similarity) / (2.0 * sigma**2) - np.log(np.sqrt(2.0 * np.pi) * sigma)
        assert gaussian_similarity_log_likelihood(similarity, sigma).tobytes() == formula.tobytes()
        assert gaussian_similarity_log_likelihood(similarity, sigma, valid).tobytes() == np.where(valid, formula, -np.inf).tobytes()
