"""Single-target tracking metrics on boxes (x, y, w, h), OTB conventions where they exist.

Wu, Lim and Yang (2013/2015): centre location error (CLE), overlap (IoU),
precision curve (share of frames with CLE <= tau, tau = 0..50 px; the score is
its value at 20 px) and success curve (share of frames with IoU > theta,
theta = 0, 0.05, ..., 1; the score is its mean, the AUC).  OTB's toolkit
(``calcRectInt.m``) counts pixels inclusively, an overlap of
``min(x1 + w1 - 1, x2 + w2 - 1) - max(x1, x2) + 1`` columns, which is the
continuous ``min(x1 + w1, x2 + w2) - max(x1, x2)`` used here, over areas w * h
as there; its centres, ``x + (w - 1) / 2`` in 1-based pixels, are ours
(``x + w / 2``, 0-based) shifted by the same half pixel for every box, so the
CLE is the same.

Which frames count (:data:`COUNT_FIRST_FRAME`): the one-pass evaluation starts
from the true box in the first frame.  OTB's toolkit (``calcSeqErrRobust.m``
sets the first result to the ground truth, ``genPerfMat.m`` divides by every
frame) counts that frame, as does the GOT-10k toolkit's ``ExperimentOTB``;
GOT-10k's own evaluation (``ExperimentGOT10k.report``) leaves it out.
"""

import numpy as np

from replication.boxes import centres
from replication.metrics.means import fsum_mean

PRECISION_THRESHOLDS = np.arange(0, 51)
SUCCESS_THRESHOLDS = np.linspace(0.0, 1.0, 21)
# The OTB scores count the first frame, whose box is the given truth, as OTB's toolkit does (hspf
# evaluates on OTB sequences, its ref. [17]); False leaves it out, as GOT-10k's evaluation does.
COUNT_FIRST_FRAME = True


def scored_frames(per_frame: np.ndarray, count_first_frame: bool = COUNT_FIRST_FRAME) -> np.ndarray:
    """The frames (first axis) of a one-pass run that the OTB scores count; see :data:`COUNT_FIRST_FRAME`."""
    return np.asarray(per_frame)[0 if count_first_frame else 1 :]


def outside_image(boxes: np.ndarray, size) -> np.ndarray:
    """Whether each box's centre lies outside an image of ``size`` (width, height): boxes (..., 4) -> (...)."""
    points = centres(boxes)
    return (points < 0).any(axis=-1) | (points[..., 0] >= size[0]) | (points[..., 1] >= size[1])


def deviation(estimates: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Per-frame (column, row) deviation of the estimated centre from the true one, in px (fusion_pf Fig. 3)."""
    return centres(estimates) - centres(truth)


def centre_error(estimates: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Euclidean distance between box centres, per frame."""
    return np.linalg.norm(deviation(estimates, truth), axis=-1)


def iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Intersection over union of boxes, per frame; 0 when the union is empty."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    left = np.maximum(a[..., 0], b[..., 0])
    top = np.maximum(a[..., 1], b[..., 1])
    right = np.minimum(a[..., 0] + a[..., 2], b[..., 0] + b[..., 2])
    bottom = np.minimum(a[..., 1] + a[..., 3], b[..., 1] + b[..., 3])
    inter = np.clip(right - left, 0, None) * np.clip(bottom - top, 0, None)
    union = a[..., 2] * a[..., 3] + b[..., 2] * b[..., 3] - inter
    return np.divide(inter, union, out=np.zeros_like(inter), where=union > 0)


def precision_curve(errors: np.ndarray, thresholds: np.ndarray = PRECISION_THRESHOLDS) -> np.ndarray:
    """Share of frames with CLE <= tau for each threshold tau."""
    return (np.asarray(errors)[None, :] <= np.asarray(thresholds)[:, None]).mean(axis=1)


def precision_at(errors: np.ndarray, threshold: float = 20.0) -> float:
    """OTB precision score: share of frames with CLE <= 20 px."""
    return float((np.asarray(errors) <= threshold).mean())


def success_curve(overlaps: np.ndarray, thresholds: np.ndarray = SUCCESS_THRESHOLDS) -> np.ndarray:
    """Share of frames with IoU > theta for each threshold theta (strictly greater, as OTB)."""
    return (np.asarray(overlaps)[None, :] > np.asarray(thresholds)[:, None]).mean(axis=1)


def success_auc(overlaps: np.ndarray) -> float:
    """OTB success score: the mean of the 21-point success curve."""
    return fsum_mean(success_curve(overlaps))


# "Correct tracking" is undefined in ism_pf and fusion_pf: each rule is a per-frame test.
CORRECT_RULES = {
    "iou>=0.5": lambda errors, overlaps: overlaps >= 0.5,
    "iou>0": lambda errors, overlaps: overlaps > 0.0,
    "cle<=20": lambda errors, overlaps: errors <= 20.0,
    "cle<=10": lambda errors, overlaps: errors <= 10.0,
}


def correct_frames(errors: np.ndarray, overlaps: np.ndarray, rule: str) -> np.ndarray:
    if rule not in CORRECT_RULES:
        raise ValueError(f"unknown correctness rule {rule!r}; choose one of {sorted(CORRECT_RULES)}")
    return CORRECT_RULES[rule](np.asarray(errors), np.asarray(overlaps))


def tracked_to_end(correct: np.ndarray, patience: int = 10) -> bool:
    """A run tracks to the end when it is correct in the last frame and never wrong for ``patience`` frames in a row."""
    correct = np.asarray(correct, dtype=bool)
    if len(correct) == 0 or not correct[-1]:
        return False
    wrong = np.concatenate([[0], (~correct).astype(int), [0]])
    starts, ends = np.flatnonzero(np.diff(wrong) == 1), np.flatnonzero(np.diff(wrong) == -1)
    return bool(np.all(ends - starts < patience))
