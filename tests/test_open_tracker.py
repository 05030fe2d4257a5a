"""Births, deaths and the detection-fused proposal on cases with exact answers (issue 17, item 2)."""

from dataclasses import dataclass

import numpy as np
import pandas as pd
import pytest
from scipy.stats import multivariate_normal

from replication.filters.registry import builder
from replication.filters.open_tracker import ParticleTracker
from replication.filters.track_management import Deleter, Initiator, associate
from replication.models.boosted import BoostedBoxModel
from replication.vision.colour import ColourLikelihood
from replication.vision.histogram import ColourHistogram


def test_associate_takes_the_overlapping_detection_and_rejects_below_the_gate():
    tracks = np.array([[0, 0, 10, 10], [100, 100, 10, 10]], float)
    detections = np.array([[101, 101, 10, 10], [50, 50, 10, 10], [1, 0, 10, 10]], float)
    assert associate(tracks, detections, 0.3).tolist() == [2, 0]
    assert associate(tracks, detections[1:2], 0.3).tolist() == [-1, -1]


def test_a_detection_is_born_on_its_third_consecutive_frame_and_not_when_a_track_explains_it():
    births = Initiator(frames=3, min_iou=0.3, explained_iou=0.3)
    person, none = np.array([[10.0, 10, 20, 40]]), np.zeros((0, 4))
    assert len(births.step(person, none)) == 0
    assert len(births.step(person + 1, none)) == 0
    assert births.step(person + 2, none).tolist() == (person + 2).tolist()  # frame 3: born
    explained = Initiator(frames=1)
    assert len(explained.step(person, person + 1)) == 0  # a track already sits on it
    gap = Initiator(frames=3)
    gap.step(person, none), gap.step(none, none), gap.step(person, none)
    assert len(gap.step(person, none)) == 0  # the streak restarted after the gap: 2 frames so far


def test_a_track_dies_after_its_unsupported_frames_or_when_it_leaves_the_image():
    deaths = Deleter(frames=3, min_rho=0.7)
    assert deaths.supported(np.array([True, False, False]), np.array([0.1, 0.8, 0.6])).tolist() == [True, True, False]
    boxes = np.array([[10, 10, 20, 40], [10, 10, 20, 40], [95, 10, 20, 40]], float)
    causes = deaths.causes(np.array([2, 3, 0]), boxes, (100, 100))
    assert causes["unsupported"].tolist() == [False, True, False]  # 3 frames unsupported
    assert causes["outside"].tolist() == [False, False, True]  # centre x = 105 is outside
    assert (causes["unsupported"] | causes["outside"]).tolist() == [False, True, True]  # the tracker's deaths
    assert Deleter(frames=3, min_rho=None).supported(np.array([True, False]), np.array([0.1, 1.0])).tolist() == [
        True, False]  # detections alone support it


def _model(alpha, detection=None):
    model = BoostedBoxModel(np.array([50.0, 50, 20, 40]), None, step_sd=(4.0, 4.0, 1.0, 2.0), alpha=alpha,
                            detection_sd=(0.1, 0.1, 0.05, 0.05))
    model.detection = detection
    return model


def test_the_proposal_is_the_prior_without_a_detection_or_with_alpha_zero():
    previous = np.tile([50.0, 50, 20, 40], (5, 1))
    for model in (_model(0.5), _model(0.0, np.array([60.0, 50, 20, 40]))):
        moved, correction = model.propose(previous, 1, np.random.default_rng(3))
        assert np.array_equal(moved, model.propagate(previous, 1, np.random.default_rng(3)))
        assert correction == 0.0


def test_the_importance_correction_is_log_prior_over_the_mixture_density():
    detection = np.array([60.0, 52, 22, 38])
    model = _model(0.3, detection)
    previous = np.array([[50.0, 50, 20, 40], [58.0, 51, 21, 39]])
    moved, correction = model.propose(previous, 1, np.random.default_rng(0))
    prior = [multivariate_normal(p, np.diag(np.square([4.0, 4.0, 1.0, 2.0]))).pdf(x) for p, x in zip(previous, moved)]
    near = multivariate_normal(detection, np.diag(np.square([2.2, 3.8, 1.1, 1.9]))).pdf(moved)
    assert np.allclose(correction, np.log(prior) - np.log(0.3 * near + 0.7 * np.array(prior)), rtol=1e-10)


def test_importance_weights_make_the_mixture_unbiased_for_the_prior():
    """E_q[f p / q] = E_p[f]: with a flat likelihood the weighted mean is the prior's (the ancestor)."""
    model = _model(0.7, np.array([70.0, 40, 24, 44]))
    previous = np.tile([50.0, 50, 20, 40], (400_000, 1))
    moved, correction = model.propose(previous, 1, np.random.default_rng(1))
    weights = np.exp(correction)
    assert weights.mean() == pytest.approx(1.0, abs=0.02)
    assert (weights @ moved / weights.sum()) == pytest.approx([50.0, 50, 20, 40], abs=0.15)


class _Flat:
    """A colour likelihood that is the same everywhere: what is left of the likelihood is the detection term."""

    def prepare(self, frame):
        return None

    def log_likelihood(self, boxes, prepared):
        return np.full(len(boxes), -1.5)


def test_the_detection_term_adds_the_detections_gaussian_log_density_to_the_colour_likelihood():
    model = BoostedBoxModel(np.array([50.0, 50, 20, 40]), _Flat(), step_sd=(4.0, 4.0, 1.0, 2.0),
                            detection_term=(0.1, 0.1, 0.05, 0.05))
    particles = np.array([[50.0, 50, 20, 40], [61.0, 47, 23, 41]])
    assert model.log_likelihood(particles, None, 1).tolist() == [-1.5, -1.5]  # no detection this frame
    model.detection = np.array([60.0, 52, 22, 38])
    sd = np.array([2.2, 3.8, 1.1, 1.9])  # 0.1 w, 0.1 h, 0.05 w, 0.05 h of the detection
    expected = -1.5 + multivariate_normal(model.detection, np.diag(sd**2)).logpdf(particles)
    assert np.allclose(model.log_likelihood(particles, None, 1), expected, rtol=1e-12)
    untermed = BoostedBoxModel(np.array([50.0, 50, 20, 40]), _Flat(), step_sd=(4.0, 4.0, 1.0, 2.0))
    untermed.detection = model.detection
    assert untermed.log_likelihood(particles, None, 1).tolist() == [-1.5, -1.5]  # Okuma et al.: proposal only
    with pytest.raises(ValueError, match="detection_term"):
        BoostedBoxModel(np.array([50.0, 50, 20, 40]), None, detection_term=(0.1, 0.0, 0.1, 0.1))


@dataclass
class _Square:
    """A MOT-like sequence: one red square on grey, frames 3-10 detected, gone from frame 11."""

    size = (120, 90)
    n_frames = 16
    detections = pd.DataFrame(
        [(f, 40.0 + f, 30.0, 16.0, 16.0, 1.0) for f in range(3, 11)], columns=["frame", "x", "y", "w", "h", "score"])

    def image(self, frame):
        image = np.full((90, 120, 3), 128, np.uint8)
        if frame <= 10:
            image[30:46, 40 + frame: 56 + frame] = (30, 30, 220)
        return image


@pytest.mark.parametrize("method", ["mipf", "bis", "mfmc", "dmot", "mcmc"])
def test_a_target_is_born_from_persistent_detections_and_dies_after_its_absence(method):
    params = {"n_particles": 200} if method != "bis" else {"n_particles": 200, "n_joint": 500}
    cache: dict = {}

    def new_model(image, box):
        histogram = ColourHistogram(bins=(8, 8, 4), kernel="epanechnikov", grid=(8, 8))
        return BoostedBoxModel(box, ColourLikelihood.from_frame(image, box, histogram, 0.1), cache=cache,
                               step_sd=(2.0, 2.0, 0.5, 0.5), alpha=0.5)

    tracker = ParticleTracker(builder(method)(**params), new_model, Initiator(frames=3), Deleter(frames=3, min_rho=0.7))
    out = {frame: ids.tolist() for frame, ids, _ in tracker.track(_Square(), range(1, 17), np.random.default_rng(0))}
    assert all(out[f] == [] for f in (1, 2, 3, 4))  # detected from frame 3: born on its third, frame 5
    assert all(out[f] == [1] for f in range(5, 11))
    assert all(out[f] == [] for f in range(11, 17))  # gone: unsupported from 11, dead at 13, never output again
    assert tracker.born == 1
    # born at 5; live frames 6..13 (8), detected 6..10 (5), the grey background never supports it (rho < 0.7),
    # output on 5..10 (6), dead at 13 on its third unsupported frame
    assert tracker.counts == {"births": 1, "track_frames": 8, "detected_frames": 5, "colour_frames": 0,
                              "shown_frames": 6, "died_unsupported": 1, "died_outside": 0}


def test_output_detected_shows_a_track_only_in_the_frames_a_detection_is_associated_with_it():
    class Gappy(_Square):
        detections = _Square.detections[_Square.detections["frame"] != 8]  # a missed detection at frame 8

        def image(self, frame):
            return _Square().image(min(frame, 10))  # the square stays: its colour supports it at frame 8

    cache: dict = {}

    def new_model(image, box):
        histogram = ColourHistogram(bins=(8, 8, 4), kernel="epanechnikov", grid=(8, 8))
        return BoostedBoxModel(box, ColourLikelihood.from_frame(image, box, histogram, 0.1), cache=cache,
                               step_sd=(2.0, 2.0, 0.5, 0.5), alpha=0.5)

    for output, shown in (("supported", True), ("detected", False)):
        tracker = ParticleTracker(builder("mipf")(n_particles=200), new_model, Initiator(frames=2),
                                  Deleter(frames=3, min_rho=0.7), output=output)
        out = {frame: ids.tolist() for frame, ids, _ in tracker.track(Gappy(), range(1, 12), np.random.default_rng(0))}
        assert out[7] == out[9] == [1] and (out[8] == [1]) is shown


def test_the_matched_centre_error_averages_the_centre_distances_of_the_clear_mot_matches():
    from replication.metrics.mot import clear_mot_matches, matched_centre_error

    truth = pd.DataFrame([(1, 1, 0, 0, 10, 10), (1, 2, 50, 0, 10, 10), (2, 1, 0, 0, 10, 10)],
                         columns=["frame", "id", "x", "y", "w", "h"])
    found = pd.DataFrame([(1, 7, 1, 0, 10, 10), (1, 8, 90, 90, 10, 10), (2, 7, 0, 2, 10, 10)],
                         columns=["frame", "id", "x", "y", "w", "h"])
    matches = clear_mot_matches(truth, found)
    assert matches[["frame", "truth_id", "hypothesis_id"]].values.tolist() == [[1, 1, 7], [2, 1, 7]]
    assert matched_centre_error(truth, found, matches) == pytest.approx((1.0 + 2.0) / 2)  # track 8 matches nothing


def test_a_patience_in_seconds_is_converted_by_the_frame_rate_and_one_in_frames_is_kept():
    from replication.filters.track_management import in_frames

    assert in_frames({"seconds": 0.7, "min_rho": None}, 7.0) == {"frames": 5, "min_rho": None}  # 4.9 frames
    assert in_frames({"seconds": 0.7}, 25.0) == {"frames": 18}  # 17.5 rounds to even: 18
    assert in_frames({"seconds": 0.01}, 7.0) == {"frames": 1}  # never less than a frame
    assert in_frames({"frames": 3, "min_iou": 0.3}, 30.0) == {"frames": 3, "min_iou": 0.3}
    with pytest.raises(ValueError, match="not both"):
        in_frames({"frames": 3, "seconds": 1.0}, 7.0)


def test_a_track_whose_box_is_off_its_person_explains_the_persons_detection_by_cover_not_by_iou():
    """The detection (20 x 40) lies wholly inside a track's box twice its size: IoU 0.5 x 0.5 = 0.25 < 0.3, so the
    IoU rule starts a second track on the person; the cover rule (the detection's whole area is inside) does not."""
    person, track = np.array([[10.0, 10, 20, 40]]), np.array([[0.0, 0, 40, 80]])
    from replication.filters.track_management import cover_matrix

    assert cover_matrix(person, track)[0, 0] == 1.0 and cover_matrix(track, person)[0, 0] == 0.25
    assert len(Initiator(frames=1, explained_iou=0.3).step(person, track)) == 1
    assert len(Initiator(frames=1, explained_iou=0.3, explained_by="cover").step(person, track)) == 0
    with pytest.raises(ValueError, match="explained_by"):
        Initiator(explained_by="centre")


@pytest.mark.parametrize("box", ["estimate", "detection", "average"])
def test_a_shown_track_outputs_its_estimate_the_associated_detection_or_their_mean(box):
    """The square's detections are offset 4 px to the right of it: with ``box: detection`` every frame with a
    detection outputs exactly the detection's box, with ``average`` the mean of it and the filter's estimate."""
    class Offset(_Square):
        detections = _Square.detections.assign(x=_Square.detections["x"] + 4.0)

    cache: dict = {}

    def new_model(image, box_):
        histogram = ColourHistogram(bins=(8, 8, 4), kernel="epanechnikov", grid=(8, 8))
        return BoostedBoxModel(box_, ColourLikelihood.from_frame(image, box_, histogram, 0.1), cache=cache,
                               step_sd=(2.0, 2.0, 0.5, 0.5), alpha=0.5)

    outputs = {}
    for kind in ("estimate", box):
        tracker = ParticleTracker(builder("mipf")(n_particles=200), new_model, Initiator(frames=2),
                                  Deleter(frames=3, min_rho=None), output="detected", box=kind)
        outputs[kind] = {f: b for f, ids, b in tracker.track(Offset(), range(1, 12), np.random.default_rng(0)) if len(ids)}
    given = {int(f): rows[["x", "y", "w", "h"]].to_numpy(float) for f, rows in Offset.detections.groupby("frame")}
    for frame in range(5, 11):  # tracked frames after the birth frame (4), each with its detection
        expected = {"estimate": outputs["estimate"][frame], "detection": given[frame],
                    "average": (outputs["estimate"][frame] + given[frame]) / 2}[box]
        assert np.allclose(outputs[box][frame], expected, rtol=0, atol=1e-12)
    assert not np.allclose(outputs["estimate"][6], given[6])  # the estimate is the filter's own box
    with pytest.raises(ValueError, match="unknown box"):
        ParticleTracker(builder("mipf")(n_particles=10), new_model, Initiator(), Deleter(), box="median")


def test_a_patience_whose_frames_are_unset_by_a_config_takes_its_seconds():
    from replication.filters.track_management import in_frames

    assert in_frames({"frames": None, "seconds": 1.4, "min_rho": None}, 14.0) == {"frames": 20, "min_rho": None}
