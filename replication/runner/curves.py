"""Curves over frames and thresholds as tidy tables: what the report's curve figures draw, computed from
the runs' per-frame series, and what the paper-scale record keeps in place of the series.

Each is registered under the figure kind that draws it (:data:`CURVES`: the kinds whose
:class:`~replication.evidence.figures.FigureSpec` is ``curved``); it takes the runs (a records table with
``per_frame``), the figure's typed spec and the experiment, and gives one row per point of a line,
in the order the lines are drawn (conditions, then methods, as the runs come).  :func:`curve_table` is
the table of one figure spec.  A table that needs the video the runs saw (the image's size) reads it from
the :class:`~replication.evidence.footage.Footage` given.  They live here, below the evidence and the report,
since they compute with the metrics (compiled code): the caller hands the tables up to the figures.
"""

import numpy as np
import pandas as pd

from replication.evidence.curves import clip_diverged, clip_level, figure_runs
from replication.evidence.figures import FigureSpec
from replication.evidence.footage import Footage
from replication.kinds import Registry
from replication.metrics import tracking as tm

CURVES: Registry = Registry("curve table")  # a curved figure kind -> the table it draws


def curve_table(records: pd.DataFrame, spec: FigureSpec, experiment: dict, footage: Footage) -> pd.DataFrame:
    """The table figure ``spec`` (a curved kind) draws, from the runs of its ``conditions`` (all, if it names
    none); empty if none of them was run."""
    if spec.conditions is not None:
        records = records[figure_runs(records, spec)]
    return CURVES[spec.kind](records, spec, experiment, footage) if len(records) else pd.DataFrame()


@CURVES.register("per_frame_curve")
def per_frame_band(records: pd.DataFrame, spec: FigureSpec, experiment: dict, footage: Footage) -> pd.DataFrame:
    """Per condition, method and frame, the mean and 10-90 % band over runs of the per-frame series
    ``spec.series`` (a run diverged beyond the condition's :func:`~replication.evidence.curves.clip_level` is
    clipped, and counted in ``diverged``); frames no run estimates and methods that do not record the series
    are left out."""
    rows = []
    for condition, group in records.groupby("condition", sort=False):
        curves = _per_frame(group, spec.series)
        typical = max((np.nanmax(np.nanmedian(np.abs(v), axis=0)) for _, v in curves.values()), default=np.nan)
        level = clip_level(spec.clip, typical)
        for method, (frames, values) in curves.items():
            values, diverged = clip_diverged(values, level)
            low, high = np.nanpercentile(values, [10, 90], axis=0)
            rows.append(pd.DataFrame({"condition": condition, "method": method, "frame": frames,
                                      "mean": np.nanmean(values, axis=0), "low": low, "high": high,
                                      "runs": len(diverged), "diverged": int(diverged.sum())}))
    return pd.concat(rows, ignore_index=True) if rows else pd.DataFrame(
        columns=["condition", "method", "frame", "mean", "low", "high", "runs", "diverged"])


@CURVES.register("otb_curves")
def otb_curves(records: pd.DataFrame, spec: FigureSpec, experiment: dict, footage: Footage) -> pd.DataFrame:
    """OTB's one-pass precision and success curves per method: each the mean over runs of the run's curve
    (over the frames :func:`~replication.metrics.tracking.scored_frames` counts), with ``score`` the mean
    precision at 20 px or success AUC (the legend's number)."""
    rows = []
    for method, runs in records.groupby("method", sort=False):
        errors = [tm.scored_frames(np.asarray(r["cle"], dtype=float)) for r in runs["per_frame"]]
        overlaps = [tm.scored_frames(np.asarray(r["iou"], dtype=float)) for r in runs["per_frame"]]
        for curve, thresholds, values, score in (
                ("precision", tm.PRECISION_THRESHOLDS, np.mean([tm.precision_curve(e) for e in errors], axis=0),
                 np.mean([tm.precision_at(e) for e in errors])),
                ("success", tm.SUCCESS_THRESHOLDS, np.mean([tm.success_curve(o) for o in overlaps], axis=0),
                 np.mean([tm.success_auc(o) for o in overlaps]))):
            rows.append(pd.DataFrame({"method": method, "curve": curve, "threshold": thresholds.astype(float),
                                      "value": values, "score": score}))
    return pd.concat(rows, ignore_index=True)


@CURVES.register("outside_curve")
def outside_share(records: pd.DataFrame, spec: FigureSpec, experiment: dict, footage: Footage) -> pd.DataFrame:
    """Per method and frame, the share of estimated centres outside the image (the filter's own state),
    over runs and targets."""
    size = footage.seen(experiment, records).size
    rows = []
    for method, runs in records.groupby("method", sort=False):
        outside = tm.outside_image(np.array([r["box"] for r in runs["per_frame"]], dtype=float), size)
        rows.append(pd.DataFrame({"method": method, "frame": np.arange(outside.shape[1]),
                                  "share": outside.mean(axis=(0, 2))}))
    return pd.concat(rows, ignore_index=True)


def _per_frame(group: pd.DataFrame, series: str) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each method's frames (1-based) and runs x frames values of a per-frame series, without the frames
    no run estimates (the given first one); methods that do not record it (alpha_k: fusion filters
    only) are left out."""
    curves = {}
    for method, runs in group.groupby("method", sort=False):
        if series not in runs["per_frame"].iloc[0]:
            continue
        values = np.array([r[series] for r in runs["per_frame"]], dtype=float)
        kept = ~np.isnan(values).all(axis=0)
        curves[method] = (np.arange(1, values.shape[1] + 1)[kept], values[:, kept])
    return curves
