"""MOT metrics on boxes (hand cases, py-motmetrics on real sequences) and the SORT / detections-only references."""

import numpy as np
import pandas as pd
import pytest
from mot_cases import motmetrics_accumulator, needs_mot, table, two_walkers

from replication.filters.mot_baselines import detections_only, sort
from replication.metrics.mot import drop_ignored, iou_matrix, mot_metrics
from replication.scenes import load_mot


def test_iou_matrix_hand_values():
    a = np.array([[0, 0, 10, 10], [100, 100, 5, 5]], float)
    b = np.array([[0, 0, 10, 10], [5, 0, 10, 10], [0, 0, 0, 0]], float)
    np.testing.assert_allclose(iou_matrix(a, b), [[1, 1 / 3, 0], [0, 0, 0]])
    assert iou_matrix(a, np.zeros((0, 4))).shape == (2, 0)


def test_perfect_tracker():
    truth = two_walkers()
    result = mot_metrics(truth, truth.assign(id=truth["id"] + 10))
    assert (result["mota"], result["idf1"], result["motp"]) == (1.0, 1.0, 0.0)
    assert result["switches"] == result["fragmentations"] == result["false_positives"] == result["misses"] == 0


def test_ids_swapped_halfway():
    truth = two_walkers()
    hyp = truth.assign(id=np.where((truth["frame"] > 5) == (truth["id"] == 1), 2, 1))
    result = mot_metrics(truth, hyp)
    assert result["switches"] == 2 and result["fragmentations"] == 0
    assert result["mota"] == pytest.approx(1 - 2 / 20)
    assert result["idf1"] == pytest.approx(2 * 10 / 40)  # each truth keeps one hypothesis for 5 of its 10 frames


def test_fragmentation_and_miss():
    truth = two_walkers()
    hyp = truth[~((truth["id"] == 1) & truth["frame"].isin([4, 5]))]
    result = mot_metrics(truth, hyp)
    assert (result["misses"], result["fragmentations"], result["switches"]) == (2, 1, 0)


def test_a_box_on_an_ignore_region_counts_nothing():
    truth = two_walkers(3)
    ignored = table([(k, 99, 500, 300, 30, 60) for k in (1, 2, 3)])
    on_ignore = table([(2, 7, 503, 300, 30, 60)])  # IoU 0.82 with the ignore box
    beside_it = table([(3, 8, 520, 300, 30, 60)])  # IoU 0.2: a false positive
    hyp = pd.concat([truth, on_ignore, beside_it], ignore_index=True)
    result = mot_metrics(truth, hyp, ignored)
    assert result["ignored_hypotheses"] == 1 and result["false_positives"] == 1
    assert result["mota"] == pytest.approx(1 - 1 / 6) and result["idf1"] == pytest.approx(12 / 13)
    # the joint assignment gives a hypothesis to the target it fits best, not to an ignore box over it
    overlapping = table([(1, 99, 18, 50, 20, 40)])  # IoU 0.74 with target 1's box
    assert len(drop_ignored(truth[truth["frame"] == 1].iloc[:1], truth, overlapping)) == 1


def motmetrics_summary(truth, hyp):
    mm = pytest.importorskip("motmetrics")
    acc = motmetrics_accumulator(truth, hyp)
    metrics = ["mota", "motp", "idf1", "num_switches", "num_fragmentations", "num_false_positives"]
    return mm.metrics.create().compute(acc, metrics=metrics, name="x").iloc[0]


@needs_mot
@pytest.mark.parametrize("tracker", [sort, detections_only])
@pytest.mark.parametrize("name", ["PETS09-S2L1", "TUD-Campus"])
def test_agrees_with_motmetrics_on_real_sequences(name, tracker):
    sequence = load_mot(name)
    hyp = tracker(sequence.detections)
    ours = mot_metrics(sequence.truth, hyp, sequence.ignored)
    kept = drop_ignored(hyp, sequence.truth, sequence.ignored)
    theirs = motmetrics_summary(sequence.truth, kept)
    assert ours["ignored_hypotheses"] == len(hyp) - len(kept) and (len(kept) < len(hyp)) == (not sequence.ignored.empty)
    for key, their_key in [("mota", "mota"), ("motp", "motp"), ("idf1", "idf1")]:
        assert ours[key] == pytest.approx(theirs[their_key], abs=1e-12)
    assert ours["switches"] == theirs["num_switches"]
    assert ours["fragmentations"] == theirs["num_fragmentations"]
    assert ours["false_positives"] == theirs["num_false_positives"]


def walker_detections(missing=()):
    det = two_walkers(20).drop(columns="id").assign(score=1.0)
    return det[~((det["x"] < 200) & det["frame"].isin(missing))].reset_index(drop=True)


def test_sort_keeps_ids_over_a_gap_shorter_than_max_age_and_births_after_min_hits():
    det = walker_detections(missing=(8, 9))  # the first walker is not detected in frames 8 and 9
    tracks = sort(det, min_hits=3, max_age=3)
    assert sorted(tracks["id"].unique()) == [1, 2]
    assert tracks.groupby("id")["frame"].min().tolist() == [3, 3]  # born at the third consecutive match
    first = tracks[tracks["x"] < 200]
    assert first["id"].nunique() == 1 and sorted(first["frame"]) == [3, 4, 5, 6, 7, *range(10, 21)]
    assert mot_metrics(two_walkers(20), tracks)["switches"] == 0
    # with max_age = 2 the track dies in the gap: a new one is born three frames after the walker reappears
    reborn = sort(det, min_hits=3, max_age=2)
    assert reborn.groupby("id")["frame"].min().tolist() == [3, 3, 12]


def test_detections_only_links_neighbours_and_restarts_after_a_gap():
    tracks = detections_only(walker_detections(missing=(8,)))
    assert tracks.groupby("id")["frame"].agg(["min", "max"]).values.tolist() == [[1, 7], [1, 20], [9, 20]]


def test_the_three_errors_of_two_balls_that_swap():
    """Two balls 40 px apart whose estimates swap at frame 5 (hand case): the per-identity error is 40 px
    from then on, the identity-free error and OSPA stay 0, and the error while tracked counts only the
    frames before each loss; one close encounter when they pass within 20 px."""
    from replication.metrics import multi

    truth = np.zeros((10, 2, 2))
    truth[:, 1, 0] = 40.0
    estimates = truth.copy()
    estimates[5:] = truth[5:, ::-1]
    assert multi.mean_error_per_target(estimates, truth) == 20.0  # 40 px in half of the frames
    assert multi.identity_free_error(estimates, truth) == 0.0
    assert multi.ospa(estimates, truth, cutoff=20.0) == 0.0
    onsets = multi.loss_onsets(estimates, truth, threshold=20.0, patience=3)
    assert list(onsets) == [5, 5]  # both lost (an onset before the last frame)
    assert multi.tracked_error(estimates, truth, onsets) == 0.0
    off = truth + np.array([30.0, 0.0])  # 30 px right of its own ball: the first 10 px from the second ball
    # the best assignment crosses: (10 + min(70, 20)) / 2 = 15, against (min(30, 20) + min(30, 20)) / 2 = 20
    assert multi.ospa(off, truth, cutoff=20.0) == pytest.approx(15.0)
    passing = truth.copy()
    passing[3:6, 1, 0] = 10.0  # ball 2 comes within 20 px for frames 3-5, once
    assert multi.close_encounters(passing, 20.0) == 1 and multi.close_encounters(truth, 20.0) == 0


def test_detection_overlap_is_one_for_the_detections_themselves_and_the_mean_best_iou_otherwise():
    from replication.metrics.mot import detection_overlap

    detections = pd.DataFrame([(1, 0, 0, 10, 10, 1.0), (1, 50, 0, 10, 10, 1.0), (2, 0, 0, 10, 10, 1.0)],
                              columns=["frame", "x", "y", "w", "h", "score"])
    own = detections.assign(id=[1, 2, 1])[["frame", "id", "x", "y", "w", "h"]]
    assert detection_overlap(own, detections) == pytest.approx(1.0)
    shifted = pd.DataFrame([(1, 1, 5, 0, 10, 10), (3, 1, 0, 0, 10, 10)], columns=["frame", "id", "x", "y", "w", "h"])
    # frame 1: IoU 50 / 150 with the first detection; frame 3 has none: 0
    assert detection_overlap(shifted, detections) == pytest.approx((50 / 150 + 0.0) / 2)
    assert np.isnan(detection_overlap(shifted.iloc[:0], detections))


def test_by_frame_is_the_groupby_it_replaced():
    """Frames in order of first appearance, rows in table order, ids, boxes and row labels as the
    DataFrame groupby gave them; a table without ids gets -1."""
    from replication.metrics.mot import BOX, by_frame

    rng = np.random.default_rng(2)
    frames = rng.integers(1, 30, 400)
    tab = pd.DataFrame({"frame": frames, "id": rng.integers(1, 9, 400), **{c: rng.uniform(0, 99, 400) for c in BOX}},
                       index=rng.permutation(1000)[:400])
    split = by_frame(tab)
    groups = list(tab.groupby("frame", sort=False))
    assert list(split) == [frame for frame, _ in groups]
    for frame, rows in groups:
        np.testing.assert_array_equal(split[frame].ids, rows["id"].to_numpy())
        np.testing.assert_array_equal(split[frame].boxes, rows[BOX].to_numpy())
        assert list(split[frame].index) == list(rows.index)
    assert by_frame(tab.drop(columns="id"))[frames[0]].ids.tolist() == [-1] * int((frames == frames[0]).sum())
    assert by_frame(tab.iloc[:0]) == {}


def test_boosted_proposal_density_is_scipys_normal():
    from scipy.stats import norm

    from replication.models.boosted import normal_logpdf

    rng = np.random.default_rng(3)
    x = rng.normal(100, 30, (3000, 4))
    x[0, 0], x[1, 1] = np.inf, -np.inf
    for mean, sd in ((rng.normal(100, 30, 4), rng.uniform(0.1, 20, 4)), (x[::-1] + 1.0, np.array([3.0, 3.0, 0.3, 0.3]))):
        ours, scipys = normal_logpdf(x, mean, sd), norm.logpdf(x, mean, sd)
        assert np.array_equal(ours.view(np.int64), scipys.view(np.int64))  # the same bits, infinities included
