"""Reference multi-target trackers on a MOT sequence's public detections, for context beside the particle filters.

Both map ``detections`` (columns frame, x, y, w, h, score, as
:func:`replication.scenes.mot.load_mot` gives them) to a hypothesis track table with
columns frame, id, x, y, w, h (ids from 1), the input of
:func:`replication.metrics.mot.mot_metrics`.  They are not particle filters and take no
images, hence their own module rather than a builder in ``FILTERS``.

- :func:`detections_only`: each frame's detections, each linked to one of the previous
  frame's by the Hungarian method on IoU; no motion model, no memory across a gap.
- :func:`sort`: SORT (Bewley, Ge, Ott, Ramos and Upcroft, "Simple Online and Realtime
  Tracking", ICIP 2016, arXiv:1602.00763), written from the paper.
"""

import numpy as np
import pandas as pd

from replication.boxes import centres, corner_boxes
from replication.metrics.mot import BOX, match_boxes

COLUMNS = ["frame", "id", *BOX]


def detection_boxes(detections: pd.DataFrame, min_score: float) -> dict[int, np.ndarray]:
    """Each frame's (N, 4) detection boxes (x, y, w, h) of score at least ``min_score``."""
    kept = detections[detections["score"] >= min_score]
    return {int(frame): rows[BOX].to_numpy(float) for frame, rows in kept.groupby("frame")}


def _frames(detections: pd.DataFrame, min_score: float):
    """(frame, (N, 4) boxes) for every frame from 1 to the last detection's, boxes of score >= ``min_score``."""
    boxes = detection_boxes(detections, min_score)
    last = int(detections["frame"].max()) if len(detections) else 0
    for frame in range(1, last + 1):
        yield frame, boxes.get(frame, np.zeros((0, 4)))


def _table(rows: list) -> pd.DataFrame:
    return pd.DataFrame(rows, columns=COLUMNS).astype({"frame": int, "id": int})


def detections_only(detections: pd.DataFrame, min_score: float = -np.inf, min_iou: float = 0.3) -> pd.DataFrame:
    """Detections linked frame to frame: a detection takes the id of the previous frame's box it is assigned to
    (Hungarian, IoU >= ``min_iou``, SORT's 0.3 so the two references differ only in SORT's filter and track
    management), else a new id.  Every detection is output, so unmatched clutter is a one-frame track."""
    rows, previous, previous_ids, next_id = [], np.zeros((0, 4)), np.zeros(0, int), 1
    for frame, boxes in _frames(detections, min_score):
        ids = np.zeros(len(boxes), int)
        old, new = match_boxes(previous, boxes, min_iou)
        ids[new] = previous_ids[old]
        fresh = ids == 0
        ids[fresh] = np.arange(next_id, next_id + fresh.sum())
        next_id += int(fresh.sum())
        rows.extend((frame, i, *box) for i, box in zip(ids, boxes))
        previous, previous_ids = boxes, ids
    return _table(rows)


# SORT's Kalman filter: state (cx, cy, s, r, vcx, vcy, vs), s the box area and r = w / h the aspect ratio,
# constant velocity per frame for cx, cy and s, r constant (Bewley et al. 2016, section 3.2).  The paper
# gives no noise values; ours, in px and px^2, per frame: measurement standard deviations
# (4 px, 4 px, 1000 px^2, 0.05), process (1, 1, 100, 0.01) on the observed parts and (0.5 px, 0.5 px,
# 100 px^2) on the velocities, the velocities initialised at 0 with "large" deviations (10 px, 10 px,
# 1000 px^2) as the paper says.
F = np.eye(7) + np.eye(7, k=4)
H = np.eye(4, 7)
R = np.diag([4.0, 4.0, 1000.0, 0.05]) ** 2
Q = np.diag([1.0, 1.0, 100.0, 0.01, 0.5, 0.5, 100.0]) ** 2
P0 = np.diag([4.0, 4.0, 1000.0, 0.05, 10.0, 10.0, 1000.0]) ** 2


def _to_measurement(boxes: np.ndarray) -> np.ndarray:
    w, h = boxes[:, 2], boxes[:, 3]
    return np.column_stack([centres(boxes), w * h, w / h])


def _to_box(states: np.ndarray) -> np.ndarray:
    area, ratio = np.clip(states[:, 2], 1e-6, None), states[:, 3]
    w = np.sqrt(area * ratio)
    h = area / w
    return corner_boxes(np.column_stack([states[:, :2], w, h]))


def sort(
    detections: pd.DataFrame, min_score: float = -np.inf, min_iou: float = 0.3, min_hits: int = 3, max_age: int = 1
) -> pd.DataFrame:
    """SORT: per frame, predict every track, assign detections to predicted boxes by the Hungarian method on
    IoU (pairs below ``min_iou`` rejected) and update the matched tracks with their detection.

    An unmatched detection starts a tentative track; it is born (gets an id and is output) at its
    ``min_hits``-th consecutive match, and stays born.  A track unmatched for ``max_age`` consecutive frames
    is deleted.  Output: the born tracks' updated boxes in the frames they are matched.  The paper's
    IoU_min = 0.3 and T_Lost = 1 are the defaults; the paper states a probationary period without a
    length, min_hits = 3 is the authors' released default.  A predicted area that would turn negative
    has its area velocity zeroed.
    """
    x, p = np.zeros((0, 7)), np.zeros((0, 7, 7))
    streak, missed, ids = np.zeros(0, int), np.zeros(0, int), np.zeros(0, int)
    rows, next_id = [], 1
    for frame, boxes in _frames(detections, min_score):
        x[x[:, 2] + x[:, 6] <= 0, 6] = 0.0
        x, p = x @ F.T, F @ p @ F.T + Q
        tracks, found = match_boxes(_to_box(x), boxes, min_iou)
        if len(tracks):
            z = _to_measurement(boxes[found])
            gain = p[tracks] @ H.T @ np.linalg.inv(H @ p[tracks] @ H.T + R)
            x[tracks] += (gain @ (z - x[tracks] @ H.T)[:, :, None])[:, :, 0]
            p[tracks] = (np.eye(7) - gain @ H) @ p[tracks]
        new = np.setdiff1d(np.arange(len(boxes)), found)
        x = np.vstack([x, np.hstack([_to_measurement(boxes[new]), np.zeros((len(new), 3))])])
        p = np.concatenate([p, np.broadcast_to(P0, (len(new), 7, 7))])
        streak, missed, ids = (np.concatenate([a, np.zeros(len(new), int)]) for a in (streak, missed, ids))
        matched = np.zeros(len(x), bool)
        matched[tracks] = matched[len(x) - len(new) :] = True
        streak, missed = np.where(matched, streak + 1, 0), np.where(matched, 0, missed + 1)
        born = (ids == 0) & (streak >= min_hits)
        ids[born] = np.arange(next_id, next_id + born.sum())
        next_id += int(born.sum())
        shown = matched & (ids > 0)
        rows.extend((frame, i, *box) for i, box in zip(ids[shown], _to_box(x[shown])))
        alive = missed < max_age
        x, p, streak, missed, ids = (a[alive] for a in (x, p, streak, missed, ids))
    return _table(rows)
