"""A run's condition: the values its experiment's swept variables take, as values.

A condition is ordered pairs (variable, value), in the order the sweeps are
declared: ``(("N", 100), ("scene", "Girl"))``.  Its label ``N=100;scene=Girl``
is derived, for display, file names and a run's identity (its seed streams and
stored file name hash the label, so common random numbers hold), and is never
parsed back: a run's record carries each variable as its own column
``condition.<variable>`` (:func:`columns`), which tables, figures and rankings
read (:func:`values_of`, :func:`label_of`).
"""

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import pandas as pd

PREFIX = "condition."  # a record's column for a condition variable: condition.N, condition.scene
SHORT_NAMES = {"n_particles": "N", "steps": "T", "n_joint": "K"}  # the papers' letters for swept parameters


@dataclass(frozen=True)
class Condition:
    """The swept variables' values of a run, in sweep order (empty: a run of an experiment that sweeps
    nothing)."""

    values: tuple[tuple[str, Any], ...] = ()

    @classmethod
    def of(cls, assignments: Iterable[tuple[str, Any]]) -> "Condition":
        """From (parameter, value) pairs, each parameter under its paper's letter (n_particles -> N)."""
        return cls(tuple((SHORT_NAMES.get(name, name), value) for name, value in assignments))

    def __str__(self) -> str:
        return ";".join(f"{name}={value}" for name, value in self.values)

    def __bool__(self) -> bool:
        return bool(self.values)

    def get(self, variable: str, default: Any = None) -> Any:
        return dict(self.values).get(variable, default)

    def without(self, *variables: str) -> "Condition":
        return Condition(tuple((name, value) for name, value in self.values if name not in variables))

    def columns(self) -> dict[str, Any]:
        """The record's columns: {'condition.N': 100, 'condition.scene': 'Girl'}."""
        return {f"{PREFIX}{name}": value for name, value in self.values}


def values_of(records: pd.DataFrame, variable: str | None) -> pd.Series:
    """The value of ``variable`` in each row of ``records`` (None where a row's condition lacks it, and in
    every row for no variable)."""
    column = f"{PREFIX}{variable}"
    if variable is None or column not in records:
        return pd.Series([None] * len(records), index=records.index, dtype=object)
    return records[column].astype(object).where(records[column].notna(), None)


def label_of(records: pd.DataFrame, without: Iterable[str | None] = (), sep: str = ";") -> pd.Series:
    """Each row's condition as its label, less the variables ``without``: 'N=100' for a row at N=100 and
    scene Girl without 'scene'; '' where nothing is left."""
    skipped = {f"{PREFIX}{v}" for v in without if v}
    variables = [c for c in records.columns if c.startswith(PREFIX) and c not in skipped]
    return pd.Series([_label(row, variables, sep) for row in records[variables].to_dict("records")] if variables
                     else [""] * len(records), index=records.index, dtype=object)


def _label(row: Mapping[str, Any], variables: list[str], sep: str) -> str:
    return sep.join(f"{c[len(PREFIX):]}={row[c]}" for c in variables if row[c] is not None and not pd.isna(row[c]))
