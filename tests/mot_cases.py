"""What the MOT tests share: whether the MOTChallenge data are beside the project, box tables,
hand-made walkers, and py-motmetrics' accumulator over box IoU (the independent reference)."""

import numpy as np
import pandas as pd
import pytest

from replication.paths import resolve
from replication.scenes.mot import MOT_ROOT

HAVE_MOT = (resolve(MOT_ROOT) / "PETS09-S2L1" / "gt" / "gt.txt").exists()
needs_mot = pytest.mark.skipif(not HAVE_MOT, reason="../shared/data/mot is not beside the project")
COLUMNS = ["frame", "id", "x", "y", "w", "h"]


def table(rows):
    return pd.DataFrame(rows, columns=COLUMNS).astype({"frame": int, "id": int})


def two_walkers(frames=10):
    """Two people 200 px apart, each 20 x 40 px, walking right at 5 px per frame; ids 1 and 2."""
    return table([(k, i, 10 + 5 * k + 200 * (i - 1), 50, 20, 40) for k in range(1, frames + 1) for i in (1, 2)])


def motmetrics_accumulator(truth: pd.DataFrame, hyp: pd.DataFrame):
    """py-motmetrics' MOTAccumulator fed every frame's 1 - IoU distances, pairs below IoU 0.5 not allowed."""
    mm = pytest.importorskip("motmetrics")
    acc = mm.MOTAccumulator(auto_id=False)
    for frame in sorted(set(truth["frame"]) | set(hyp["frame"])):
        t, h = truth[truth["frame"] == frame], hyp[hyp["frame"] == frame]
        boxes_t, boxes_h = t[COLUMNS[2:]].to_numpy(float), h[COLUMNS[2:]].to_numpy(float)
        distance = 1 - mm.distances.boxiou(boxes_t[:, None], boxes_h[None])  # iou_matrix needs np.asfarray
        acc.update(t["id"].tolist(), h["id"].tolist(), np.where(distance <= 0.5, distance, np.nan), frameid=frame)
    return acc
