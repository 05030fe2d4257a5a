"""Tracking metrics on hand-computed cases, and CLEAR MOT / IDF1 against py-motmetrics."""

import math

import numpy as np
import pytest

from replication.boxes import centre_boxes, centres, corner_boxes
from replication.metrics import multi
from replication.metrics import tracking as tm
from replication.metrics.means import fsum_mean


def test_centre_error_iou_and_deviation_hand_computed():
    truth = np.array([[0, 0, 10, 10], [0, 0, 10, 10], [0, 0, 10, 10]], float)
    est = np.array([[0, 0, 10, 10], [5, 0, 10, 10], [20, 20, 10, 10]], float)
    np.testing.assert_allclose(tm.centre_error(est, truth), [0, 5, np.hypot(20, 20)])
    np.testing.assert_allclose(tm.iou(est, truth), [1.0, 50 / 150, 0.0])
    np.testing.assert_allclose(tm.deviation(est, truth), [[0, 0], [5, 0], [20, 20]])
    assert tm.iou(np.array([0, 0, 0, 0.0]), np.array([0, 0, 0, 0.0])) == 0.0


def test_precision_and_success_curves_follow_otb():
    errors = np.array([0.0, 10.0, 20.0, 30.0])
    assert tm.precision_at(errors) == 0.75  # <= 20 px
    curve = tm.precision_curve(errors)
    assert curve[0] == 0.25 and curve[20] == 0.75 and curve[50] == 1.0 and len(curve) == 51
    overlaps = np.array([0.0, 0.5, 1.0])
    success = tm.success_curve(overlaps)
    assert len(success) == 21 and success[0] == pytest.approx(2 / 3)  # IoU > 0, strictly
    assert success[10] == pytest.approx(1 / 3)  # IoU > 0.5 strictly: only the perfect frame
    assert success[-1] == 0.0
    assert tm.success_auc(overlaps) == pytest.approx(success.mean())
    assert tm.success_auc(np.ones(5)) == pytest.approx(20 / 21)  # IoU = 1 fails only "> 1"


def test_correct_tracking_rules_and_tracked_to_end():
    errors, overlaps = np.array([5.0, 25.0, 8.0]), np.array([0.6, 0.0, 0.4])
    np.testing.assert_array_equal(tm.correct_frames(errors, overlaps, "iou>=0.5"), [True, False, False])
    np.testing.assert_array_equal(tm.correct_frames(errors, overlaps, "cle<=20"), [True, False, True])
    with pytest.raises(ValueError, match="unknown correctness rule"):
        tm.correct_frames(errors, overlaps, "vibes")
    assert tm.tracked_to_end(np.array([1, 0, 0, 1, 1], bool), patience=3)
    assert not tm.tracked_to_end(np.array([1, 0, 0, 0, 1], bool), patience=3)
    assert not tm.tracked_to_end(np.array([1, 1, 1, 1, 0], bool), patience=3)


def test_mean_error_per_target_and_track_loss():
    truth = np.zeros((4, 2, 2))
    est = np.zeros((4, 2, 2))
    est[:, 1, 0] = [3, 30, 30, 4]
    assert multi.mean_error_per_target(est, truth) == pytest.approx((3 + 30 + 30 + 4) / 8)
    np.testing.assert_array_equal(multi.loss_onsets(est, truth, threshold=10, patience=2), [4, 1])  # 4: never
    np.testing.assert_array_equal(multi.loss_onsets(est, truth, threshold=10, patience=3), [4, 4])


def test_clear_mot_hand_case_with_a_swap():
    # two targets 100 px apart; the tracker's estimates swap identities in frame 2
    truth = np.array([[[0, 0], [100, 0]]] * 3, float)
    est = np.array([[[1, 0], [100, 2]], [[1, 0], [100, 2]], [[100, 1], [0, 1]]], float)
    result = multi.clear_mot(truth, est, threshold=10)
    assert result["switches"] == 2 and result["misses"] == 0 and result["false_positives"] == 0
    assert result["mota"] == pytest.approx(1 - 2 / 6)
    assert result["motp"] == pytest.approx((1 + 2 + 1 + 2 + 1 + 1) / 6)
    assert multi.idf1(truth, est, threshold=10) == pytest.approx(2 * 4 / 12)


def motmetrics_summary(truth, est, threshold, truth_present, est_present):
    mm = pytest.importorskip("motmetrics")
    acc = mm.MOTAccumulator(auto_id=True)
    for k in range(len(truth)):
        oids, hids = np.flatnonzero(truth_present[k]), np.flatnonzero(est_present[k])
        d = np.linalg.norm(truth[k, oids][:, None] - est[k, hids][None], axis=-1)
        acc.update(oids.tolist(), hids.tolist(), np.where(d < threshold, d, np.nan))
    summary = mm.metrics.create().compute(acc, metrics=["mota", "motp", "idf1", "num_switches", "num_fragmentations"], name="x")
    return summary.iloc[0]


@pytest.mark.parametrize("seed", range(6))
def test_clear_mot_and_idf1_agree_with_motmetrics(seed):
    rng = np.random.default_rng(seed)
    frames, targets = 40, 5
    truth = np.cumsum(rng.normal(0, 3, (frames, targets, 2)), axis=0) + rng.uniform(0, 60, (1, targets, 2))
    est = truth + rng.normal(0, 4, truth.shape)
    swap = rng.integers(10, 30)
    est[swap:, [0, 1]] = est[swap:, [1, 0]]  # an identity swap
    truth_present = rng.random((frames, targets)) > 0.1
    est_present = rng.random((frames, targets)) > 0.15
    ours = multi.clear_mot(truth, est, 8.0, truth_present, est_present)
    theirs = motmetrics_summary(truth, est, 8.0, truth_present, est_present)
    assert ours["mota"] == pytest.approx(theirs["mota"])
    assert ours["motp"] == pytest.approx(theirs["motp"])
    assert ours["switches"] == theirs["num_switches"]
    assert ours["fragmentations"] == theirs["num_fragmentations"]
    assert multi.idf1(truth, est, 8.0, truth_present, est_present) == pytest.approx(theirs["idf1"])


def test_a_score_is_the_mean_of_its_exact_sum_rounded_once_in_whatever_order():
    """A hand case where a left-to-right sum (0: each 1 is lost against 1e16), numpy's pairwise sum (14: eight
    accumulators, one of them holding 1e16) and the exact sum (15) all differ: the scores' mean is the
    exact sum over the count, math.fsum's, for the values in any order or layout."""
    values = np.array([1e16] + [1.0] * 15 + [-1e16])
    left_to_right = 0.0
    for value in values:
        left_to_right += value
    assert (left_to_right, float(np.sum(values)), math.fsum(values)) == (0.0, 14.0, 15.0)
    assert fsum_mean(values) == math.fsum(values) / 17 == 15 / 17
    assert fsum_mean(values[::-1]) == fsum_mean(values.reshape(17, 1).T) == fsum_mean(values.tolist()) == 15 / 17
    assert math.isnan(fsum_mean([])) and math.isnan(fsum_mean([1.0, math.nan]))
    with np.errstate(over="ignore", invalid="ignore"):  # numpy's answers where no float holds the exact sum
        assert fsum_mean([math.inf, 1.0]) == math.inf and fsum_mean([1e308, 1e308]) == math.inf
        assert math.isnan(fsum_mean([math.inf, -math.inf]))


def test_the_multi_target_errors_are_their_distances_exact_means():
    """mean_error_per_target, identity_free_error, OSPA (p = 1) and the error while tracked are the fsum means
    of their distances: the hand case's 1e16 would lose the unit distances in a running sum."""
    truth = np.zeros((4, 2, 2))
    estimates = truth.copy()
    estimates[:, 0, 0] = [1e16, 1.0, 1.0, -0.0]  # target 0's distances: 1e16, 1, 1, 0
    estimates[:, 1, 1] = 1.0  # target 1 off by 1 px in every frame
    distances = np.linalg.norm(estimates - truth, axis=-1)
    assert multi.mean_error_per_target(estimates, truth) == math.fsum(distances.ravel()) / 8 == (1e16 + 6) / 8
    onsets = np.array([1, 4])  # target 0 lost from frame 1: its first frame, and target 1's four
    assert multi.tracked_error(estimates, truth, onsets) == (1e16 + 4) / 5
    assert multi.ospa(estimates, truth, cutoff=20.0) == (10.5 + 1 + 1 + 0.5) / 4


def test_one_box_conversion_both_ways():
    """Corner (x, y, w, h) and centre (cx, cy, w, h) boxes: x + w / 2 (the same bits as x + 0.5 w), back to the
    corner within rounding, exactly for whole-pixel boxes, a state's further coordinates (velocity) ignored."""
    rng = np.random.default_rng(5)
    boxes = np.column_stack([rng.uniform(-50, 500, (200, 2)), rng.uniform(0.5, 80, (200, 2))])
    centred = centre_boxes(boxes)
    np.testing.assert_array_equal(centred, np.column_stack([boxes[:, :2] + 0.5 * boxes[:, 2:], boxes[:, 2:]]))
    np.testing.assert_array_equal(centres(boxes), centred[:, :2])
    np.testing.assert_allclose(corner_boxes(centred), boxes, rtol=0, atol=1e-12)
    whole = np.array([[3, 4, 10, 7], [0, 0, 1, 1]])  # a synthetic scene's truth: integers
    np.testing.assert_array_equal(corner_boxes(centre_boxes(whole)), whole)
    assert corner_boxes(np.array([10.0, 20.0, 4.0, 6.0, 1.0, -1.0])).tolist() == [8.0, 17.0, 4.0, 6.0]
