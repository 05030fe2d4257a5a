"""Summaries over runs: one estimate per (method, condition), its interval fitting the metric."""

import pandas as pd

from replication.condition import PREFIX, values_of
from replication.evidence.quantities import quantity
from replication.evidence.statistics import estimate


def scene_of(experiment: dict, records: pd.DataFrame) -> str:
    """The scene the runs of one condition ran on (their ``condition.scene``), else the experiment's one
    scene."""
    scene = values_of(records, "scene").iloc[0] if len(records) else None
    return scene or experiment["model"]["scene"]


def summarise(records: pd.DataFrame, metric: str, scale: float = 1.0, statistic: str = "mean") -> pd.DataFrame:
    """One row per (method, condition): runs, the statistic, its 95% interval (``ci_low``, ``ci_high``),
    how the interval was made, the variance over runs, the per-run values (``values``) and the condition's
    variables (``condition.<variable>``).  ``scale`` converts units (100: a percentage)."""
    kind = quantity(metric).scaled(scale)
    variables = [c for c in records.columns if c.startswith(PREFIX)]
    rows = []
    read = records[list(dict.fromkeys(["method", "condition", metric, *variables]))]  # not every column copied
    for (method, condition), group in read.groupby(["method", "condition"], sort=False):
        values = group[metric].astype(float) * scale
        found = estimate(values.to_numpy(), kind, statistic)
        rows.append({
            "method": method,
            "condition": condition,
            "runs": found.runs,
            "mean": found.value,
            "ci_low": found.low,
            "ci_high": found.high,
            "interval": found.method,
            "variance": float(values.var(ddof=1)) if found.runs > 1 else float("nan"),
            "values": values.to_numpy(),
            **group[variables].iloc[0].to_dict(),
        })
    return pd.DataFrame(rows, columns=["method", "condition", "runs", "mean", "ci_low", "ci_high", "interval",
                                       "variance", "values", *variables])
