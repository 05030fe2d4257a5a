"""How a curve figure picks its runs and where it cuts a diverged one: the rules the figures and the curve
tables (:mod:`replication.runner.curves`, computed below the report from the runs' per-frame series) share."""

import numpy as np
import pandas as pd

from replication.evidence.named_conditions import as_mappings, matching


def clip_level(clip: float | None, typical: float) -> float | None:
    """Where a diverged run is cut: the figure's ``clip:``, else 10 times the typical magnitude given
    (none when that is 0 or unknown)."""
    if clip is not None:
        return float(clip)
    level = 10 * abs(typical)
    return level if np.isfinite(level) and level > 0 else None


def clip_diverged(values, level: float | None) -> tuple[np.ndarray, np.ndarray]:
    """``values`` (one per run, or runs x frames) with each non-finite one or one beyond ``level`` in
    size put at the level (left out where there is none); and which runs diverged so."""
    values = np.asarray(values, dtype=float)
    bad = ~np.isfinite(values)
    if level is not None:
        bad |= np.abs(values) > level
    edge = np.sign(np.nan_to_num(values, nan=1.0)) * (np.nan if level is None else level)
    diverged = bad if values.ndim == 1 else bad.any(axis=1)
    return np.where(bad, edge, values), diverged


def figure_conditions(spec) -> list[dict]:
    """The ``conditions`` figure ``spec`` is drawn at, each a mapping of values
    (:mod:`~replication.evidence.named_conditions`); none: every condition."""
    return as_mappings(spec.conditions, f"figure {spec.name!r}: conditions")


def figure_runs(records: pd.DataFrame, spec) -> pd.Series:
    """Which of ``records`` figure ``spec`` draws, where it names ``conditions``: the runs at one of them."""
    return matching(records, *figure_conditions(spec))
