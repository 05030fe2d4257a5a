"""HOTA of a hypothesis track table against MOT ground truth, computed by TrackEval.

HOTA, Higher Order Tracking Accuracy (Luiten, Osep, Dendorfer, Torr, Geiger, Leal-Taixe and
Leibe, "HOTA: A Higher Order Metric for Evaluating Multi-Object Tracking", IJCV 129:548-578,
2021, doi:10.1007/s11263-020-01375-2), weighs detection and association equally.  At a
localisation threshold alpha, truth and hypothesis boxes are matched one-to-one per frame
(pairs with IoU >= alpha, chosen by a Hungarian assignment that favours pairs whose tracks
align well over the whole sequence), giving TP, FN and FP counts; then

    DetA = |TP| / (|TP| + |FN| + |FP|),
    AssA = (1 / |TP|) sum over c in TP of |TPA(c)| / (|TPA(c)| + |FNA(c)| + |FPA(c)|),
    HOTA_alpha = sqrt(DetA * AssA),

where TPA(c) are the matches of c's truth id with c's hypothesis id, FNA(c) the other frames
of that truth id and FPA(c) the other frames of that hypothesis id.  LocA is the mean IoU of
the matches.  Every score is averaged over alpha = 0.05, 0.10, ..., 0.95, as TrackEval and
the MOTChallenge leaderboards report them (HOTA is the mean of HOTA_alpha, not sqrt of the
means).

Tables are those of :mod:`replication.metrics.mot` (columns frame, id, x, y, w, h; 0-based
top-left boxes).  Ignore boxes (ground-truth flag 0) are handled exactly as
:func:`replication.metrics.mot.mot_metrics` handles them, by
:func:`replication.metrics.mot.drop_ignored`: a hypothesis that the per-frame joint
Hungarian assignment gives to an ignore box with IoU >= ``min_iou`` (0.5) is removed, and
ignore boxes are never truth.  This is TrackEval's MOT16/17 preprocessing for distractor
boxes, applied here to flag-0 boxes; TrackEval's MOT15 setting only drops flag-0 truth.

The IoU matrices are this module's (:func:`replication.metrics.mot.iou_matrix`); the metric
itself is TrackEval's ``trackeval.metrics.HOTA().eval_sequence`` (the ``trackeval``
package, a dependency), fed the data dict a TrackEval dataset's
``get_preprocessed_seq_data`` returns: per frame the truth and hypothesis ids relabelled
0..n-1 and the truth x hypothesis similarity matrix.
"""

import numpy as np
import pandas as pd
from trackeval.metrics import HOTA

from replication.metrics.means import fsum_mean
from replication.metrics.mot import NO_ROWS, by_frame, drop_ignored, iou_matrix

SCORES = {  # our key: TrackEval's field, averaged over alpha
    "hota": "HOTA",
    "deta": "DetA",
    "assa": "AssA",
    "loca": "LocA",
    "detre": "DetRe",
    "detpr": "DetPr",
    "assre": "AssRe",
    "asspr": "AssPr",
}


def _check_unique(table: pd.DataFrame, name: str) -> None:
    repeated = table[table.duplicated(["frame", "id"])]
    if not repeated.empty:
        frame, i = repeated.iloc[0][["frame", "id"]]
        raise ValueError(f"{name}: id {i} appears more than once in frame {frame}")


def hota_data(
    truth: pd.DataFrame, hypotheses: pd.DataFrame, ignored: pd.DataFrame | None = None, min_iou: float = 0.5
) -> dict:
    """TrackEval's per-sequence data dict (IoU similarities) after the ignore rule; input to any TrackEval metric."""
    kept = hypotheses if ignored is None else drop_ignored(hypotheses, truth, ignored, min_iou)
    _check_unique(truth, "truth")
    _check_unique(kept, "hypotheses")
    truth_ids, hypothesis_ids = np.unique(truth["id"]), np.unique(kept["id"])
    tru, hyp = by_frame(truth), by_frame(kept)
    data = {"gt_ids": [], "tracker_ids": [], "similarity_scores": []}
    for frame in sorted(tru.keys() | hyp.keys()):
        t, h = tru.get(frame, NO_ROWS), hyp.get(frame, NO_ROWS)
        data["gt_ids"].append(np.searchsorted(truth_ids, t.ids))
        data["tracker_ids"].append(np.searchsorted(hypothesis_ids, h.ids))
        data["similarity_scores"].append(iou_matrix(t.boxes, h.boxes))
    data.update(
        num_timesteps=len(data["gt_ids"]),
        num_gt_ids=len(truth_ids),
        num_tracker_ids=len(hypothesis_ids),
        num_gt_dets=len(truth),
        num_tracker_dets=len(kept),
    )
    return data


def hota(
    truth: pd.DataFrame, hypotheses: pd.DataFrame, ignored: pd.DataFrame | None = None, min_iou: float = 0.5
) -> dict:
    """HOTA, DetA, AssA, LocA (and DetRe, DetPr, AssRe, AssPr), each averaged over alpha; ``hota_0`` at alpha 0.05.

    ``min_iou`` is only the ignore rule's threshold (as in ``mot_metrics``); HOTA sweeps its own alphas.
    """
    data = hota_data(truth, hypotheses, ignored, min_iou)
    res = HOTA().eval_sequence(data)
    return {
        **{key: fsum_mean(res[field]) for key, field in SCORES.items()},
        "hota_0": float(res["HOTA(0)"]),
        "loca_0": float(res["LocA(0)"]),
    }
