"""Where a tracker's false positives and misses come from, frame by frame (the ``mot_breakdown`` table).

CLEAR MOT counts a hypothesis box without a match at IoU >= ``min_iou`` as a false positive
and a person without one as a miss.  A box that follows its person but fits badly counts
twice (a false positive and a miss) though the person is tracked; a second track on a
tracked person counts once.  :func:`error_sources` splits both counts by cause, given the
matches :func:`replication.metrics.mot.clear_mot_matches` made:

* a false positive is *off its person* when it overlaps (IoU >= ``near_iou``) a person no
  box matched, *a duplicate* when the person it overlaps most is matched to another box,
  and *on the background* otherwise; ``off_person_detected`` counts the off boxes whose
  person a detection covers (IoU >= ``min_iou``): the box could have been the detection's;
* a miss is *a box off* when an unmatched box overlaps the person (IoU >= ``near_iou``),
  *detected* when no box does but a detection covers it (the tracker output nothing there:
  no track yet, or one lost or not shown), and *undetected* otherwise (no detection either);
* ``duplicate_births``: tracks whose first box matches (IoU >= ``min_iou``) a person another
  track was matched to in that frame or the one before: a second track started on a person
  a live one covers;
* ``scale_log_ratio``: the mean over matches of log(box area / person's area) (0: the right
  size; log 2: boxes twice too large).

Each split adds up to the count it splits (``false_positives``, ``misses``).
"""

import numpy as np
import pandas as pd

from replication.metrics.means import fsum_mean
from replication.metrics.mot import BOX, NO_ROWS, by_frame, iou_matrix

NEAR_IOU = 0.1  # a box this close to a person is about it (our choice: a tenth of IoU, half a box's width off)


def error_sources(truth: pd.DataFrame, hypotheses: pd.DataFrame, detections: pd.DataFrame, matches: pd.DataFrame,
                  min_iou: float = 0.5, near_iou: float = NEAR_IOU) -> dict[str, float]:
    """The false positives and misses of ``hypotheses`` against ``truth`` split by cause (module docstring);
    ``matches`` are :func:`~replication.metrics.mot.clear_mot_matches`' rows for the same tables."""
    tru, hyp, det = by_frame(truth), by_frame(hypotheses), by_frame(detections)
    pairs = {frame: (set(rows["truth_id"]), set(rows["hypothesis_id"]))
             for frame, rows in matches.groupby("frame")}
    counts = dict.fromkeys(["fp_off_person", "off_person_detected", "fp_duplicate", "fp_background",
                            "miss_box_off", "miss_detected", "miss_undetected"], 0)
    for frame in tru.keys() | hyp.keys():
        t, h, d = tru.get(frame, NO_ROWS), hyp.get(frame, NO_ROWS), det.get(frame, NO_ROWS)
        matched_truth, matched_hyp = pairs.get(frame, (set(), set()))
        free_t = ~np.isin(t.ids, list(matched_truth))
        free_h = ~np.isin(h.ids, list(matched_hyp))
        overlap = iou_matrix(h.boxes[free_h], t.boxes)  # unmatched boxes x every person
        covered = iou_matrix(t.boxes, d.boxes).max(axis=1, initial=0.0) >= min_iou  # a detection on the person
        if overlap.size:
            best = overlap.argmax(axis=1)
            near = overlap.max(axis=1) >= near_iou
            off = near & free_t[best]
            counts["fp_off_person"] += int(off.sum())
            counts["off_person_detected"] += int((off & covered[best]).sum())
            counts["fp_duplicate"] += int((near & ~free_t[best]).sum())
            counts["fp_background"] += int((~near).sum())
        else:
            counts["fp_background"] += int(free_h.sum())
        box_off = (overlap >= near_iou).any(axis=0) & free_t if overlap.size else np.zeros(len(t.ids), bool)
        counts["miss_box_off"] += int(box_off.sum())
        counts["miss_detected"] += int((free_t & ~box_off & covered).sum())
        counts["miss_undetected"] += int((free_t & ~box_off & ~covered).sum())
    return {**counts, "duplicate_births": _duplicate_births(truth, hypotheses, matches, min_iou),
            "scale_log_ratio": _scale_log_ratio(truth, hypotheses, matches)}


def _duplicate_births(truth: pd.DataFrame, hypotheses: pd.DataFrame, matches: pd.DataFrame, min_iou: float) -> int:
    """Tracks whose first box matches (IoU >= ``min_iou``) a person matched to another track in that frame or
    the one before."""
    if hypotheses.empty:
        return 0
    firsts = hypotheses.sort_values("frame", kind="stable").drop_duplicates("id")
    holders = matches.groupby(["frame", "truth_id"])["hypothesis_id"].agg(set).to_dict()
    tru = by_frame(truth)
    duplicates = 0
    for frame, track, box in zip(firsts["frame"], firsts["id"], firsts[BOX].to_numpy()):
        people = tru.get(frame, NO_ROWS)
        overlap = iou_matrix(box, people.boxes)[0]
        for person in people.ids[overlap >= min_iou]:
            others = (holders.get((frame, person), set()) | holders.get((frame - 1, person), set())) - {track}
            if others:
                duplicates += 1
                break
    return duplicates


def _scale_log_ratio(truth: pd.DataFrame, hypotheses: pd.DataFrame, matches: pd.DataFrame) -> float:
    """The mean over ``matches`` of log(hypothesis box area / truth box area); NaN without a match."""
    if matches.empty:
        return float("nan")
    keys = ["frame", "id"]
    true = matches.merge(truth, left_on=["frame", "truth_id"], right_on=keys, how="left")
    found = matches.merge(hypotheses, left_on=["frame", "hypothesis_id"], right_on=keys, how="left")
    return fsum_mean(np.log(found["w"] * found["h"] / (true["w"] * true["h"])).to_numpy())
