"""Summaries over runs: one estimate per (method, condition), its interval fitting the metric."""

import pandas as pd

from replication.evidence.quantities import quantity
from replication.evidence.statistics import estimate


def parse_condition(condition: str) -> dict[str, str]:
    """A run's condition as {variable: value}: 'scene=Girl;N=10' -> {'scene': 'Girl', 'N': '10'}."""
    return dict(part.split("=", 1) for part in condition.split(";") if part)


def scene_of(experiment: dict, condition: str) -> str:
    """The scene a run's condition names ('scene=Girl;N=10' -> 'Girl'), else the experiment's one scene."""
    return parse_condition(condition).get("scene") or experiment["model"]["scene"]


def summarise(records: pd.DataFrame, metric: str, scale: float = 1.0, statistic: str = "mean") -> pd.DataFrame:
    """One row per (method, condition): runs, the statistic, its 95% interval (``ci_low``, ``ci_high``),
    how the interval was made, the variance over runs and the per-run values (``values``).  ``scale`` converts units (100: a percentage)."""
    kind = quantity(metric).scaled(scale)
    rows = []
    for (method, condition), group in records.groupby(["method", "condition"], sort=False):
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
        })
    return pd.DataFrame(rows, columns=["method", "condition", "runs", "mean", "ci_low", "ci_high", "interval",
                                       "variance", "values"])
