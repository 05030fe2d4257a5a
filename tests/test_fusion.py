"""fusion_pf's observation model: eq (5) weights, the eqs (6)-(7) coefficient update, the config override."""

import numpy as np
import pytest

from replication.vision.colour import ColourLikelihood
from replication.vision.fusion import FusionLikelihood, fusion_coefficients
from replication.vision.histogram import ColourHistogram

rng = np.random.default_rng(3)
FRAME = rng.integers(0, 256, (80, 100, 3), dtype=np.uint8)
BOX = np.array([50.0, 40.0, 24.0, 16.0])


def fusion(**kwargs):
    histogram = ColourHistogram(bins=(8, 8, 2), kernel="diagonal", grid=(24, 16))
    return FusionLikelihood.from_frame(FRAME, BOX, histogram, **kwargs)


def test_coefficients_follow_eqs_6_and_7():
    assert fusion_coefficients(0.9, 0.3) == pytest.approx((0.75, 0.25))
    assert fusion_coefficients(0.5, 0.5) == pytest.approx((0.5, 0.5))
    assert fusion_coefficients(0.8, -0.4) == (1.0, 0.0)  # negative SSIM counts as no structure
    assert fusion_coefficients(0.0, 0.0) == (1.0, 0.0)


def test_reference_box_has_the_top_weight_of_eq_5():
    model = fusion(sigma=1.0)
    log_w = model.log_likelihood(BOX[None], model.prepare(FRAME))
    assert log_w[0] == pytest.approx(-0.5 * np.log(2 * np.pi))  # rho = S = 1: w = 1 / sqrt(2 pi)


def test_fused_weight_is_the_stated_mix_of_colour_and_structure():
    model = fusion(sigma=0.5, alpha=0.3, adaptive=False)
    prepared = model.prepare(FRAME)
    boxes = BOX + np.array([[3, -2, 0, 0], [-6, 4, 2, 0], [10, 10, 0, 0]])
    rho, s, valid = model.similarities(boxes, prepared)
    assert valid.all() and (rho < 1).all() and (s < 1).all()
    expected = (0.3 * rho + 0.7 * s - 1) / (2 * 0.5**2) - np.log(np.sqrt(2 * np.pi) * 0.5)
    np.testing.assert_allclose(model.log_likelihood(boxes, prepared), expected)


def test_colour_only_is_the_colour_likelihood_and_skips_structure():
    model = fusion(sigma=0.1, alpha=1.0, adaptive=False)
    colour = ColourLikelihood(model.colour.histogram, model.colour.reference, 0.1)
    boxes = BOX + rng.normal(0, 5, (50, 4)) * [1, 1, 0.2, 0.2]
    prepared = model.prepare(FRAME)
    np.testing.assert_allclose(model.log_likelihood(boxes, prepared), colour.log_likelihood(boxes, prepared[0]))


def test_adapt_moves_alpha_to_the_similarities_at_the_estimate():
    model = fusion(alpha=0.5)
    prepared = model.prepare(FRAME)
    estimate = BOX + np.array([4.0, 3.0, 0, 0])
    rho, s, _ = model.similarities(estimate[None], prepared)
    model.adapt(estimate, prepared)
    assert model.alpha == pytest.approx(rho[0] / (rho[0] + max(s[0], 0)))
    assert model.history == [model.alpha]
    fixed = fusion(alpha=0.25, adaptive=False)
    fixed.adapt(estimate, prepared)
    assert fixed.alpha == 0.25 and fixed.history == [0.25]


def test_bad_coefficients_are_refused():
    with pytest.raises(ValueError, match="alpha"):
        fusion(alpha=1.5)


def test_a_method_observation_block_overrides_the_model_observation(make_cfg):
    from replication.runner.config import expand

    runs = expand(make_cfg("fusion_pf", "scale=quick"))
    observation = {r.method: r.model["observation"] for r in runs}
    assert observation["color-only PF"]["alpha"] == 1.0 and observation["color-only PF"]["adaptive"] is False
    assert observation["color+structure fusion PF"]["adaptive"] is True
    assert observation["fusion-sigma-0.1"]["sigma"] == 0.1 and observation["color-only PF"]["sigma"] == 1.0
    assert len({r.key for r in runs if str(r.condition) == "scene=airplane"}) == 4


def test_a_turning_plane_moves_alpha_towards_colour():
    """Eqs (6)-(7) on the airplane stand-in's sprite: on frame 0 rho' = S' = 1 gives alpha = 1/2; once the
    plane has turned 30 degrees its structure no longer matches the template, so S' < rho' and alpha > 1/2."""
    from replication.scenes import SyntheticScene

    plane = {"shape": "box", "size": [40, 24], "colour": [90, 110, 140], "colour_spread": 10, "structure": True,
             "motion": {"kind": "scripted", "keyframes": [[0, 60, 40]]}, "rotation": [[0, 0.0], [1, 30.0]]}
    scene = SyntheticScene({"size": [120, 80], "frames": 2, "background": {"kind": "flat", "colour": [170, 150, 130]},
                            "targets": [plane]})
    box = np.array([60.0, 40.0, 40.0, 24.0])
    histogram = ColourHistogram(bins=(8, 8, 2), kernel="diagonal", grid=(24, 16))
    model = FusionLikelihood.from_frame(scene.frame(0), box, histogram, square=20)
    model.adapt(box, model.prepare(scene.frame(0)))
    assert model.alpha == pytest.approx(0.5)
    rho, s, _ = model.similarities(box[None], model.prepare(scene.frame(1)))
    assert s[0] < 0.8 < rho[0]
    model.adapt(box, model.prepare(scene.frame(1)))
    assert model.alpha > 0.55 and model.history == [pytest.approx(0.5), model.alpha]
