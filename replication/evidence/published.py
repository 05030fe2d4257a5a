"""The published numbers, one row per table cell.

They ship with the package (:data:`PACKAGED`, a copy of ``../shared/reference/published_values.csv``
that the tests hold equal to it), so an installed package judges the papers' claims from any folder.
"""

import warnings
from functools import lru_cache
from pathlib import Path

import pandas as pd

from replication.condition import PREFIX
from replication.paths import resolve

PACKAGED = Path(__file__).with_name("published_values.csv")
COLUMNS = ["paper", "table", "experiment", "method", "metric", "condition", "value", "unit", "note"]


def published_path(configured: str | Path | None) -> Path:
    """The file of published values a config names (``published_values``; relative to the project
    directory), or the package's own (:data:`PACKAGED`) when it names none."""
    return PACKAGED if configured is None else resolve(configured)


@lru_cache(maxsize=4)
def load_published(path: str) -> pd.DataFrame:
    """All published cells as strings except ``value`` (numeric where it is a number).

    A missing file gives an empty table and a warning: the report then shows
    our numbers without the paper's.
    """
    if not Path(path).exists():
        warnings.warn(f"published values not found at {path}; tables will have no paper column", stacklevel=2)
        return pd.DataFrame(columns=COLUMNS + ["number"])
    table = pd.read_csv(path, dtype=str, keep_default_na=False)
    missing = set(COLUMNS) - set(table.columns)
    if missing:
        raise ValueError(f"{path} lacks columns {sorted(missing)}")
    table["number"] = pd.to_numeric(table["value"], errors="coerce")
    return pd.concat([table, _variables(table["condition"])], axis=1)


def _variables(conditions: pd.Series) -> pd.DataFrame:
    """The file writes a cell's condition as a label ('N=10;runs=100'), the one place a label is read:
    its variables as the columns our records have (``condition.N``, ``condition.runs``; strings, as every
    cell of the file).  Words that assign nothing (a note on the setting) give no column."""
    parsed = [dict(part.strip().split("=", 1) for part in text.split(";") if "=" in part and " " not in
                   part.strip()) for text in conditions]
    return pd.DataFrame([{f"{PREFIX}{k}": v for k, v in found.items()} for found in parsed], index=conditions.index,
                        dtype=object)


def cells(published: pd.DataFrame, paper: str, table, metric: str | None = None) -> pd.DataFrame:
    """The published cells of one paper table or a list of tables (and one metric, if given)."""
    tables = [str(t) for t in table] if isinstance(table, list) else [str(table)]
    chosen = (published["paper"] == paper) & published["table"].isin(tables)
    if metric is not None:
        chosen &= published["metric"] == metric
    return published[chosen]
