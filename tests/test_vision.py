"""Observation models: the vectorised histogram against a per-pixel reference, Bhattacharyya, SSIM."""

import cv2
import numpy as np
import pytest

from replication.vision import (
    ColourHistogram,
    bhattacharyya,
    bhattacharyya_distance,
    gaussian_similarity_log_likelihood,
    hsv_bin_image,
    structural_similarity,
)
from replication.vision.colour import ColourLikelihood
from replication.vision.ssim import patches

rng = np.random.default_rng(0)
FRAME = rng.integers(0, 256, (60, 80, 3), dtype=np.uint8)


def reference_histogram(frame, x0, y0, w, h, bins, kernel):
    """Straightforward per-pixel loop: the definition the vectorised code must match."""
    hsv = cv2.cvtColor(frame, cv2.COLOR_BGR2HSV).astype(int)
    bh, bs, bv = bins
    hist = np.zeros(bh * bs * bv)
    for y in range(y0, y0 + h):
        for x in range(x0, x0 + w):
            if not (0 <= x < frame.shape[1] and 0 <= y < frame.shape[0]):
                continue
            u, v = (x + 0.5 - (x0 + w / 2)) / (w / 2), (y + 0.5 - (y0 + h / 2)) / (h / 2)
            if kernel == "epanechnikov":
                weight = max(1 - u * u - v * v, 0.0)
            elif kernel == "diagonal":
                weight = 1 - ((u * w / 2) ** 2 + (v * h / 2) ** 2) / ((w / 2) ** 2 + (h / 2) ** 2)
            else:
                weight = 1.0
            b = (min(hsv[y, x, 0] * bh // 180, bh - 1) * bs + hsv[y, x, 1] * bs // 256) * bv + hsv[y, x, 2] * bv // 256
            hist[b] += weight
    return hist / hist.sum() if hist.sum() else hist


@pytest.mark.parametrize("kernel", ["epanechnikov", "diagonal", "uniform"])
@pytest.mark.parametrize("bins", [(8, 8, 4), (8, 8, 2), (6, 6, 6)])
def test_all_pixel_histograms_match_the_per_pixel_definition(kernel, bins):
    w, h = 14, 10
    histogram = ColourHistogram(bins=bins, kernel=kernel, grid=(w, h))
    boxes = np.array([[10 + w / 2, 8 + h / 2, w, h], [40 + w / 2, 30 + h / 2, w, h], [-5 + w / 2, 55 + h / 2, w, h]])
    ours = histogram.of_boxes(hsv_bin_image(FRAME, bins), boxes)
    for box, row in zip(boxes, ours):
        x0, y0 = int(box[0] - w / 2), int(box[1] - h / 2)
        np.testing.assert_allclose(row, reference_histogram(FRAME, x0, y0, w, h, bins, kernel), atol=1e-12)


@pytest.mark.parametrize("kernel", ["epanechnikov", "diagonal"])
def test_bhattacharyya_from_counts_equals_it_from_normalised_histograms(kernel):
    histogram = ColourHistogram(bins=(8, 8, 4), kernel=kernel, grid=(12, 9))
    bin_image = hsv_bin_image(FRAME, histogram.bins)
    boxes = np.column_stack([rng.uniform(-10, 90, 300), rng.uniform(-10, 70, 300), rng.uniform(3, 20, 300), rng.uniform(3, 20, 300)])
    reference = histogram.of_boxes(bin_image, np.array([[30.0, 30.0, 12.0, 9.0]]))[0]
    rho, valid = histogram.bhattacharyya(bin_image, boxes, reference)
    normalised = histogram.of_boxes(bin_image, boxes)
    np.testing.assert_allclose(rho, bhattacharyya(normalised, reference), atol=1e-12)
    np.testing.assert_array_equal(valid, normalised.sum(axis=1) > 0)
    assert (~valid).any() and valid.any()  # some boxes lie wholly outside the frame


def test_box_outside_the_image_has_an_empty_histogram_and_minus_infinity():
    histogram = ColourHistogram(grid=(10, 10))
    likelihood = ColourLikelihood.from_frame(FRAME, np.array([40, 30, 10, 10]), histogram, sigma=0.1)
    boxes = np.array([[40, 30, 10, 10], [-50, 30, 10, 10], [40, 500, 10, 10], [1, 1, 10, 10]])
    log_like = likelihood.log_likelihood(boxes, likelihood.prepare(FRAME))
    assert np.isfinite(log_like[[0, 3]]).all() and np.isneginf(log_like[[1, 2]]).all()
    assert log_like[0] == pytest.approx(-np.log(np.sqrt(2 * np.pi) * 0.1))  # rho = 1 at the reference box


def test_histogram_memory_does_not_grow_with_the_number_of_distinct_batch_sizes():
    """MCMC scores a different number of boxes each call: nothing may be kept per size (it once was: 450 MB)."""
    import tracemalloc

    histogram = ColourHistogram(grid=(10, 10))
    likelihood = ColourLikelihood.from_frame(FRAME, np.array([40, 30, 10, 10]), histogram, sigma=0.1)
    prepared = likelihood.prepare(FRAME)
    boxes = np.tile([40.0, 30.0, 10.0, 10.0], (400, 1))
    likelihood.log_likelihood(boxes, prepared)
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    for n in range(100, 400):
        likelihood.log_likelihood(boxes[:n], prepared)
    grown = tracemalloc.get_traced_memory()[0] - before
    tracemalloc.stop()
    assert grown < 100_000, grown  # 300 sizes x up to 400 boxes x 76 weights x 8 bytes = 36 MB if kept


def test_sampled_histograms_use_the_stated_number_of_points():
    histogram = ColourHistogram(bins=(6, 6, 6), samples=100, rng=np.random.default_rng(1))
    assert len(histogram.points) <= 100 and len(histogram.points) > 50  # Epanechnikov drops the corners
    flat = np.full((40, 40, 3), (10, 200, 30), np.uint8)
    result = histogram.of_boxes(hsv_bin_image(flat, (6, 6, 6)), np.array([[20, 20, 10, 10]]))
    assert result.max() == pytest.approx(1.0)  # one colour: all the mass in one bin


def test_bhattacharyya_hand_cases():
    p = np.array([0.5, 0.5, 0.0])
    assert bhattacharyya(p, p) == pytest.approx(1.0)
    assert bhattacharyya(p, np.array([0.0, 0.0, 1.0])) == 0.0
    assert bhattacharyya(p, np.array([1.0, 0.0, 0.0])) == pytest.approx(np.sqrt(0.5))
    assert bhattacharyya_distance(p, p) == pytest.approx(0.0, abs=1e-7)
    many = np.array([p, [1.0, 0.0, 0.0]])
    np.testing.assert_allclose(bhattacharyya(many, p), [1.0, np.sqrt(0.5)])


def test_gaussian_likelihood_is_ism_pf_eq_30():
    sigma, rho = 0.03, 0.99
    d2 = 1 - rho
    expected = np.log(np.exp(-d2 / (2 * sigma**2)) / (np.sqrt(2 * np.pi) * sigma))
    assert gaussian_similarity_log_likelihood(np.array([rho]), sigma)[0] == pytest.approx(expected)
    with pytest.raises(ValueError):
        gaussian_similarity_log_likelihood(np.array([rho]), 0.0)


def test_ssim_hand_computed_and_identity():
    template = rng.uniform(0, 255, (20, 20))
    assert structural_similarity(template[None], template)[0] == pytest.approx(1.0)
    other = rng.uniform(0, 255, (20, 20))
    x, y = other.ravel(), template.ravel()
    c1, c2 = (0.01 * 255) ** 2, (0.03 * 255) ** 2
    cov = np.mean((x - x.mean()) * (y - y.mean()))
    expected = (
        (2 * x.mean() * y.mean() + c1) / (x.mean() ** 2 + y.mean() ** 2 + c1)
        * (2 * x.std() * y.std() + c2) / (x.var() + y.var() + c2)
        * (cov + c2 / 2) / (x.std() * y.std() + c2 / 2)
    )
    assert structural_similarity(other[None], template)[0] == pytest.approx(expected)
    assert structural_similarity((255 - template)[None], template)[0] < 0  # inverted structure


def test_ssim_of_a_flat_patch_against_a_textured_one_is_the_formula_s_luminance_times_constants():
    """A constant patch has sd 0 and cov 0: contrast = C2 / (sd_y^2 + C2), structure = C3 / C3 = 1."""
    template = rng.uniform(0, 255, (20, 20))
    flat = np.full((20, 20), 100.0)
    c1, c2 = (0.01 * 255) ** 2, (0.03 * 255) ** 2
    mu, var = template.mean(), template.var()
    expected = (2 * 100.0 * mu + c1) / (100.0**2 + mu**2 + c1) * c2 / (var + c2)
    assert structural_similarity(flat[None], template)[0] == pytest.approx(expected)
    assert 0 < expected < 0.05  # a flat patch says almost nothing like a textured template
    assert structural_similarity(flat[None], flat)[0] == pytest.approx(1.0)  # two equal flat patches


def test_patches_read_the_box_pixels():
    grey = rng.uniform(0, 255, (50, 60)).astype(np.float32)
    got, inside = patches(grey, np.array([[20 + 10, 5 + 10, 20, 20], [-100, -100, 20, 20]]), (20, 20))
    np.testing.assert_allclose(got[0], grey[5:25, 20:40], atol=1e-3)
    assert inside[0] == 1.0 and inside[1] == 0.0
