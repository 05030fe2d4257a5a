"""HOTA (replication.metrics.hota): hand cases worked on paper, and TrackEval's own MOTChallenge evaluator on real sequences.

HOTA_alpha = sqrt(DetA_alpha * AssA_alpha) with DetA = TP / (TP + FN + FP) and AssA the mean over
matches c of TPA(c) / (TPA(c) + FNA(c) + FPA(c)); every score is the mean over the 19 alphas
0.05, 0.10, ..., 0.95.  Where every matched pair has IoU 1, all 19 alphas give the same counts.
"""

import math

import numpy as np
import pandas as pd
import pytest
import trackeval
from mot_cases import COLUMNS, needs_mot, table, two_walkers

from replication.filters.mot_baselines import sort
from replication.metrics.hota import SCORES, hota, hota_data
from replication.metrics.mot import mot_metrics
from replication.scenes import load_mot


def one_walker(frames=10):
    return two_walkers(frames).query("id == 1").reset_index(drop=True)


def test_perfect_tracking_scores_one():
    # 20 truth boxes, each matched at IoU 1: TP = 20, FN = FP = 0 at every alpha, so DetA = 1;
    # each match's pair of ids shares all 10 of their frames: TPA / (TPA + FNA + FPA) = 10 / 10, so AssA = 1.
    truth = two_walkers()
    result = hota(truth, truth.assign(id=truth["id"] + 10))
    assert result == {key: 1.0 for key in result}


def test_one_truth_track_split_between_two_hypothesis_ids():
    # Frames 1-5 carry hypothesis id 7, frames 6-10 id 8, both exactly on the truth box: DetA = 10 / 10 = 1.
    # A match in frames 1-5 has TPA = 5 (truth 1 with 7), FNA = 10 - 5 (truth 1's frames without 7), FPA = 0,
    # so 5 / 10; likewise frames 6-10: AssA = 0.5 and HOTA = sqrt(1 * 0.5), at every alpha.
    truth = one_walker()
    result = hota(truth, truth.assign(id=np.where(truth["frame"] <= 5, 7, 8)))
    assert (result["deta"], result["assa"], result["loca"]) == (1.0, 0.5, 1.0)
    assert (result["assre"], result["asspr"]) == (0.5, 1.0)  # 5 / 10 of truth 1's frames; all 5 of 7's (of 8's)
    assert result["hota"] == pytest.approx(math.sqrt(0.5), abs=1e-15)


def test_a_false_positive_costs_detection_not_association():
    # The truth copied exactly plus hypothesis 9 far from it in frames 3 and 4 (IoU 0): TP = 10, FN = 0,
    # FP = 2, so DetA = 10 / 12 and DetPr = 10 / 12, DetRe = 1; the one pair of ids is perfect, AssA = 1.
    truth = one_walker()
    stray = table([(3, 9, 400, 300, 20, 40), (4, 9, 405, 300, 20, 40)])
    result = hota(truth, pd.concat([truth, stray], ignore_index=True))
    assert result["deta"] == pytest.approx(10 / 12) and result["detpr"] == pytest.approx(10 / 12)
    assert (result["detre"], result["assa"]) == (1.0, 1.0)
    assert result["hota"] == pytest.approx(math.sqrt(10 / 12))


def test_a_shifted_box_counts_only_below_its_iou():
    # A 10 x 10 truth box and a hypothesis 5 px to its right: intersection 50, union 150, IoU 1/3.  The
    # matches count for the 6 alphas 0.05 ... 0.30 (DetA = AssA = HOTA = 1 there) and for none of the 13
    # alphas 0.35 ... 0.95 (TP = 0: DetA = AssA = HOTA = 0), so HOTA = DetA = AssA = 6 / 19.  TrackEval
    # reports LocA = 1 where there is no match (1e-10 / 1e-10): LocA = (6 * 1/3 + 13 * 1) / 19 = 15 / 19.
    truth = table([(k, 1, 0, 0, 10, 10) for k in (1, 2, 3)])
    result = hota(truth, truth.assign(id=4, x=5))
    for key in ("hota", "deta", "assa"):
        assert result[key] == pytest.approx(6 / 19)
    assert result["loca"] == pytest.approx(15 / 19)
    assert result["loca_0"] == pytest.approx(1 / 3) and result["hota_0"] == 1.0


def test_a_box_on_an_ignore_region_counts_nothing():
    # As in mot_metrics: the hypothesis on the ignore box (IoU 0.82) is removed, the one beside it (IoU 0.2)
    # stays a false positive.  TP = 6, FN = 0, FP = 1: DetA = 6 / 7, AssA = 1, HOTA = sqrt(6 / 7).
    truth = two_walkers(3)
    ignored = table([(k, 99, 500, 300, 30, 60) for k in (1, 2, 3)])
    on_ignore = table([(2, 7, 503, 300, 30, 60)])
    beside_it = table([(3, 8, 520, 300, 30, 60)])
    hyp = pd.concat([truth, on_ignore, beside_it], ignore_index=True)
    result = hota(truth, hyp, ignored)
    assert result["deta"] == pytest.approx(6 / 7) and result["assa"] == 1.0
    assert result["hota"] == pytest.approx(math.sqrt(6 / 7))
    assert hota(truth, hyp)["deta"] == pytest.approx(6 / 8)  # without the ignore boxes both are false positives


def test_no_hypotheses_scores_zero_and_repeated_ids_are_refused():
    truth = two_walkers(3)
    result = hota(truth, truth.iloc[:0])
    assert (result["hota"], result["deta"], result["assa"]) == (0.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="id 1 appears more than once in frame 1"):
        hota(truth, pd.concat([truth, truth.iloc[:1]], ignore_index=True))


def write_rows(path, rows):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join(",".join(map(repr, row)) + "\n" for row in rows))


def trackeval_on_files(tmp_path, sequence, hyp):
    """TrackEval's MOTChallenge evaluator on gt / tracker files: its own IoU, ignore preprocessing and id relabelling.

    Flag-0 boxes are written as class 8 (distractor) with flag 0, so its MOT17 preprocessing removes the
    hypotheses matched to them and drops them from the truth: the ignore rule of ``drop_ignored``.
    """
    boxes = {"truth": sequence.truth[COLUMNS], "ignored": sequence.ignored[COLUMNS]}
    gt = sorted(
        (int(f), int(i), float(x), float(y), float(w), float(h), flag, cls, 1)
        for part, flag, cls in [("truth", 1, 1), ("ignored", 0, 8)]
        for f, i, x, y, w, h in boxes[part].itertuples(index=False)
    )
    write_rows(tmp_path / "gt" / sequence.name / "gt" / "gt.txt", gt)
    write_rows(
        tmp_path / "trackers" / "sort" / "data" / f"{sequence.name}.txt",
        [(int(f), int(i), float(x), float(y), float(w), float(h), 1, -1, -1, -1)
         for f, i, x, y, w, h in hyp[COLUMNS].itertuples(index=False)],
    )
    dataset = trackeval.datasets.MotChallenge2DBox({
        "GT_FOLDER": str(tmp_path / "gt"), "TRACKERS_FOLDER": str(tmp_path / "trackers"), "BENCHMARK": "MOT17",
        "SKIP_SPLIT_FOL": True, "SEQ_INFO": {sequence.name: sequence.n_frames}, "PRINT_CONFIG": False,
    })
    quiet = {"PRINT_CONFIG": False}
    evaluator = trackeval.Evaluator({
        "PRINT_RESULTS": False, "PRINT_CONFIG": False, "TIME_PROGRESS": False, "OUTPUT_SUMMARY": False,
        "OUTPUT_DETAILED": False, "PLOT_CURVES": False, "LOG_ON_ERROR": None,
    })
    metrics = [trackeval.metrics.HOTA(), trackeval.metrics.CLEAR(quiet), trackeval.metrics.Identity(quiet)]
    results, messages = evaluator.evaluate([dataset], metrics)
    assert messages == {"MotChallenge2DBox": {"sort": "Success"}}
    return results["MotChallenge2DBox"]["sort"][sequence.name]["pedestrian"]


@needs_mot
@pytest.mark.parametrize("name", ["PETS09-S2L1", "TUD-Campus"])
def test_agrees_with_trackeval_evaluator_on_files(tmp_path, name):
    sequence = load_mot(name)
    hyp = sort(sequence.detections)
    ours = hota(sequence.truth, hyp, sequence.ignored)
    theirs = trackeval_on_files(tmp_path, sequence, hyp)
    for key, field in SCORES.items():
        assert ours[key] == pytest.approx(np.mean(theirs["HOTA"][field]), abs=1e-12), key
    assert 0 < ours["hota"] < 1 and 0 < ours["deta"] < 1 and 0 < ours["assa"] < 1
    # the same files give TrackEval's CLEAR MOT and IDF1 equal to mot_metrics' (same ignore rule)
    clear = mot_metrics(sequence.truth, hyp, sequence.ignored)
    assert clear["mota"] == pytest.approx(theirs["CLEAR"]["MOTA"], abs=1e-12)
    assert clear["idf1"] == pytest.approx(theirs["Identity"]["IDF1"], abs=1e-12)
    assert (clear["switches"], clear["false_positives"], clear["misses"]) == (
        theirs["CLEAR"]["IDSW"], theirs["CLEAR"]["CLR_FP"], theirs["CLEAR"]["CLR_FN"])


@needs_mot
def test_pets_detection_counts_are_mota_s():
    # DetA's denominator TP + FN + FP is, at every alpha, the truth boxes plus the hypotheses kept after
    # the ignore rule: TP + FN = MOTA's matches + misses, TP + FP = matches + false positives.  One
    # matching per frame serves every alpha, so TP (hence DetA) cannot grow with alpha.
    sequence = load_mot("PETS09-S2L1")
    hyp = sort(sequence.detections)
    counts = trackeval.metrics.HOTA().eval_sequence(hota_data(sequence.truth, hyp, sequence.ignored))
    clear = mot_metrics(sequence.truth, hyp, sequence.ignored)
    tp, fn, fp = counts["HOTA_TP"], counts["HOTA_FN"], counts["HOTA_FP"]
    truth_boxes, kept_hypotheses = clear["matches"] + clear["misses"], clear["matches"] + clear["false_positives"]
    assert truth_boxes == len(sequence.truth) and kept_hypotheses == len(hyp) - clear["ignored_hypotheses"]
    assert np.all(tp + fn == truth_boxes) and np.all(tp + fp == kept_hypotheses)
    assert np.all(np.diff(tp) <= 0) and np.all(np.diff(counts["DetA"]) <= 0)
    result = hota(sequence.truth, hyp, sequence.ignored)
    assert 0 < result["hota"] < 1
