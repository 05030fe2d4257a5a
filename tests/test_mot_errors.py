"""Where false positives and misses come from (replication.metrics.mot_errors), on frames with counted answers."""

import numpy as np
import pandas as pd
import pytest

from replication.metrics.mot import clear_mot_matches, mot_metrics
from replication.metrics.mot_errors import error_sources

COLUMNS = ["frame", "id", "x", "y", "w", "h"]


def _table(rows):
    return pd.DataFrame(rows, columns=COLUMNS)


def test_each_false_positive_and_miss_gets_its_cause_and_the_causes_add_up():
    """Frame 1: person 1 matched by track 7, person 2 with track 8 half a box off it (IoU 1/3) and a detection on
    it, person 3 with no box but a detection, person 4 with nothing; track 9 on the background; track 10 a second
    box on person 1.  Frame 2: person 1 matched by 7 again, track 11 born on it (a duplicate birth)."""
    truth = _table([(1, 1, 0, 0, 10, 20), (1, 2, 100, 0, 10, 20), (1, 3, 200, 0, 10, 20), (1, 4, 300, 0, 10, 20),
                    (2, 1, 0, 0, 10, 20)])
    found = _table([(1, 7, 0, 0, 10, 20), (1, 8, 105, 0, 10, 20), (1, 9, 500, 500, 10, 20), (1, 10, 2, 0, 10, 20),
                    (2, 7, 0, 0, 10, 20), (2, 11, 1, 0, 10, 20)])
    detections = _table([(1, -1, 100, 0, 10, 20), (1, -1, 200, 0, 10, 20)])
    matches = clear_mot_matches(truth, found)
    sources = error_sources(truth, found, detections, matches)
    assert {k: sources[k] for k in ("fp_off_person", "off_person_detected", "fp_duplicate", "fp_background")} == {
        "fp_off_person": 1, "off_person_detected": 1, "fp_duplicate": 2, "fp_background": 1}  # 8; 8; 10 and 11; 9
    assert {k: sources[k] for k in ("miss_box_off", "miss_detected", "miss_undetected")} == {
        "miss_box_off": 1, "miss_detected": 1, "miss_undetected": 1}  # persons 2, 3, 4
    scores = mot_metrics(truth, found)
    assert sources["fp_off_person"] + sources["fp_duplicate"] + sources["fp_background"] == scores["false_positives"]
    assert sources["miss_box_off"] + sources["miss_detected"] + sources["miss_undetected"] == scores["misses"]
    assert sources["duplicate_births"] == 2  # 10 (beside 7 in its first frame) and 11; 8 and 9 match nobody held
    assert sources["scale_log_ratio"] == 0.0  # every match is the person's own size


def test_the_scale_log_ratio_is_the_mean_log_area_ratio_of_the_matches():
    truth = _table([(1, 1, 0, 0, 10, 20), (2, 1, 0, 0, 10, 20)])
    found = _table([(1, 5, 0, 0, 11, 22), (2, 5, 0, 0, 10, 20)])  # 1.21 times the area, then exact
    sources = error_sources(truth, found, _table([]), clear_mot_matches(truth, found))
    assert sources["scale_log_ratio"] == pytest.approx(np.log(1.21) / 2, rel=1e-12)
    empty = error_sources(truth, _table([]), _table([]), clear_mot_matches(truth, _table([])))
    assert np.isnan(empty["scale_log_ratio"]) and empty["miss_undetected"] == 2 and empty["duplicate_births"] == 0
