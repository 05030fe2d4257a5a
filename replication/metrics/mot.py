"""MOT-style evaluation on boxes: CLEAR MOT and IDF1 of a hypothesis track table against MOT ground truth.

Tables are DataFrames with columns frame, id, x, y, w, h (0-based top-left boxes, as
:mod:`replication.scenes.mot` loads them).  A truth box and a hypothesis box can match
in a frame when IoU >= ``min_iou`` (0.5, MOTChallenge's threshold; Milan et al. 2016),
at distance 1 - IoU.  CLEAR MOT (Bernardin and Stiefelhagen 2008) and IDF1 (Ristani et
al. 2016) are then those of :mod:`replication.metrics.multi`, computed as py-motmetrics
does; ``motp`` is py-motmetrics' mean distance 1 - IoU over matches (MOTChallenge prints
100 (1 - motp)).

Ignore boxes (ground-truth flag 0): each frame, the hypotheses are first assigned to all
truth and ignore boxes together by the Hungarian method maximising IoU, pairs below
``min_iou`` discarded; a hypothesis assigned to an ignore box is removed, so it is
neither a false positive nor a match, and ignore boxes are never misses.  This is the
preprocessing of the MOTChallenge devkit and TrackEval (``MotChallenge2DBox``) for
MOT16/17, where it applies to distractor classes.  As far as we know TrackEval does
not remove hypotheses for MOT15 (PETS09-S2L1, TUD) and only drops the flag-0 truth
boxes, which would count hypotheses on them as false positives; we apply the MOT16/17
rule to flag-0 boxes, so our false positives on PETS09-S2L1 can be fewer than the
MOT15 leaderboard's.
"""

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.optimize import linear_sum_assignment

from replication.metrics import multi
from replication.metrics.means import fsum_mean
from replication.metrics.tracking import centre_error, iou

BOX = ["x", "y", "w", "h"]


def iou_matrix(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(N, M) IoU of boxes ``a`` (N, 4) against ``b`` (M, 4), (x, y, w, h)."""
    a, b = np.asarray(a, float).reshape(-1, 4), np.asarray(b, float).reshape(-1, 4)
    return iou(a[:, None, :], b[None, :, :])


def match_boxes(a: np.ndarray, b: np.ndarray, min_iou: float) -> tuple[np.ndarray, np.ndarray]:
    """Hungarian assignment of ``a`` to ``b`` maximising total IoU; the index pairs with IoU >= ``min_iou``."""
    overlap = iou_matrix(a, b)
    if overlap.size == 0:
        return np.zeros(0, int), np.zeros(0, int)
    rows, cols = linear_sum_assignment(np.where(overlap >= min_iou, -overlap, 0.0))
    keep = overlap[rows, cols] >= min_iou
    return rows[keep], cols[keep]


@dataclass(frozen=True)
class FrameRows:
    """One frame's rows of a box table as arrays: their ``ids`` (-1 where the table has none), ``boxes``
    (x, y, w, h) and row labels (``index``)."""

    ids: np.ndarray
    boxes: np.ndarray
    index: pd.Index


NO_ROWS = FrameRows(np.zeros(0, np.int64), np.zeros((0, 4)), pd.Index([]))


def by_frame(table: pd.DataFrame) -> dict:
    """Each frame's :class:`FrameRows`, frames in order of first appearance and rows in table order (as
    ``groupby("frame", sort=False)``), split from whole-table arrays in one pass rather than indexed out
    of a DataFrame per frame (a pandas lookup cost about 150 us, a third of a MOT run's time)."""
    codes, frames = pd.factorize(table["frame"], sort=False)
    order = np.argsort(codes, kind="stable")
    cuts = np.flatnonzero(np.diff(codes[order])) + 1
    ids = table["id"].to_numpy() if "id" in table else np.full(len(table), -1)
    boxes = table[BOX].to_numpy()
    return {frame: FrameRows(ids[rows], boxes[rows], table.index[rows])
            for frame, rows in zip(frames, np.split(order, cuts) if len(order) else [])}


def drop_ignored(
    hypotheses: pd.DataFrame, truth: pd.DataFrame, ignored: pd.DataFrame, min_iou: float = 0.5
) -> pd.DataFrame:
    """``hypotheses`` without the rows the joint assignment gives to an ignore box (module docstring)."""
    hyp, tru, ign = by_frame(hypotheses), by_frame(truth), by_frame(ignored)
    dropped = []
    for frame in hyp.keys() & ign.keys():
        targets = tru.get(frame, NO_ROWS).boxes
        rows, cols = match_boxes(hyp[frame].boxes, np.vstack([targets, ign[frame].boxes]), min_iou)
        dropped.extend(hyp[frame].index[rows[cols >= len(targets)]])
    return hypotheses.drop(index=dropped)


def frame_distances(truth: pd.DataFrame, hypotheses: pd.DataFrame, min_iou: float = 0.5):
    """Per frame with truth or hypotheses, in order: (truth ids, hypothesis ids, 1 - IoU, NaN below ``min_iou``)."""
    tru, hyp = by_frame(truth), by_frame(hypotheses)
    for frame in sorted(tru.keys() | hyp.keys()):
        t, h = tru.get(frame, NO_ROWS), hyp.get(frame, NO_ROWS)
        distance = 1.0 - iou_matrix(t.boxes, h.boxes)
        yield t.ids, h.ids, np.where(distance <= 1.0 - min_iou, distance, np.nan)


def mot_metrics(
    truth: pd.DataFrame, hypotheses: pd.DataFrame, ignored: pd.DataFrame | None = None, min_iou: float = 0.5
) -> dict:
    """MOTA, MOTP (mean 1 - IoU), IDF1, switches, fragmentations, misses, false positives, matches, ignored hypotheses."""
    kept = hypotheses if ignored is None else drop_ignored(hypotheses, truth, ignored, min_iou)
    frames = list(frame_distances(truth, kept, min_iou))
    truth_ids, hypothesis_ids = np.unique(truth["id"]), np.unique(kept["id"])
    counts = np.zeros((len(truth_ids), len(hypothesis_ids)), int)
    for oids, hids, d in frames:
        i, j = np.nonzero(np.isfinite(d))
        np.add.at(counts, (np.searchsorted(truth_ids, oids[i]), np.searchsorted(hypothesis_ids, hids[j])), 1)
    return {
        **multi.clear_mot_frames(frames),
        "idf1": multi.idf1_from_counts(counts, len(truth), len(kept)),
        "ignored_hypotheses": len(hypotheses) - len(kept),
    }


def clear_mot_matches(
    truth: pd.DataFrame, hypotheses: pd.DataFrame, ignored: pd.DataFrame | None = None, min_iou: float = 0.5
) -> pd.DataFrame:
    """The matches :func:`mot_metrics` counts, one row each: frame, truth_id, hypothesis_id, switch.

    The same matching as :func:`mot_metrics` (hypotheses on ignore boxes dropped, then
    :func:`replication.metrics.multi.match_frames` on 1 - IoU): ``switch`` marks a
    truth matched to another hypothesis than at its last match (py-motmetrics' SWITCH
    rows; the others are its MATCH rows).  Rows are in frame order.
    """
    kept = hypotheses if ignored is None else drop_ignored(hypotheses, truth, ignored, min_iou)
    numbers = sorted(set(truth["frame"]) | set(kept["frame"]))  # frame_distances' order
    matched = multi.match_frames(frame_distances(truth, kept, min_iou))
    rows = [(frame, oids[i], hids[j], switched)
            for frame, (oids, hids, _, pairs) in zip(numbers, matched) for i, j, switched in pairs]
    table = pd.DataFrame(rows, columns=["frame", "truth_id", "hypothesis_id", "switch"])
    return table.astype({"frame": int, "truth_id": int, "hypothesis_id": int, "switch": bool})


def matched_centre_error(truth: pd.DataFrame, hypotheses: pd.DataFrame, matches: pd.DataFrame) -> float:
    """bis_pf's error per target on a MOT sequence: the mean over ``matches`` (frame, truth_id,
    hypothesis_id; :func:`clear_mot_matches`) of the distance between the two boxes' centres, px."""
    if matches.empty:
        return float("nan")
    keys = ["frame", "id"]
    true = matches.merge(truth, left_on=["frame", "truth_id"], right_on=keys, how="left")
    found = matches.merge(hypotheses, left_on=["frame", "hypothesis_id"], right_on=keys, how="left")
    return fsum_mean(centre_error(found[BOX].to_numpy(), true[BOX].to_numpy()))


def detection_overlap(hypotheses: pd.DataFrame, detections: pd.DataFrame) -> float:
    """The mean, over the hypothesis boxes, of each one's highest IoU with a detection of its frame (0 in a
    frame without one): 1 for a tracker that outputs the detections themselves, lower the more its boxes
    are its own.  NaN without a hypothesis."""
    if hypotheses.empty:
        return float("nan")
    found = by_frame(detections)
    best = [iou_matrix(rows.boxes, found[frame].boxes).max(axis=1) if frame in found
            else np.zeros(len(rows.boxes)) for frame, rows in by_frame(hypotheses).items()]
    return fsum_mean(np.concatenate(best))
