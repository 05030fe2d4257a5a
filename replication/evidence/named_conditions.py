"""The conditions a claim, a table or a figure names, matched with runs' conditions as values.

A config names a condition as a mapping of variables to values, typed as YAML
gives them: ``{scene: exp2_16_targets, N: 400}``.  It holds for a run whose
condition (its record's ``condition.<variable>`` columns, or
:meth:`~replication.condition.Condition.columns`) takes every value it names,
whatever the order it names them in: a mapping naming some of the variables
holds for every run with those values.  A condition written as its label
(``"scene=x;N=10"``) is refused: a label compared as text found nothing when
written in another order than the sweeps'.
"""

import math
from collections.abc import Mapping
from numbers import Number
from typing import Any

import numpy as np
import pandas as pd

from replication.condition import PREFIX
from replication.errors import ConfigError


def as_mapping(value: Any, where: str) -> dict[str, Any]:
    """A named condition as a mapping of variables to values; a label or any other value is one
    :class:`~replication.errors.ConfigError` line naming ``where`` (a label's with the mapping to write)."""
    if isinstance(value, Mapping):
        return dict(value)
    if isinstance(value, str):
        raise ConfigError(f"{where}: write the condition {value!r} as a mapping, {instead_of(value)}")
    raise ConfigError(f"{where}: a condition is a mapping of variables to values ({{scene: Girl, N: 10}}), "
                      f"got {value!r}")


def as_mappings(values: Any, where: str) -> list[dict[str, Any]]:
    """``conditions: [..]`` (or one condition, or none: ``[]``), each as a mapping (:func:`as_mapping`)."""
    listed = [] if values is None else list(values) if isinstance(values, (list, tuple)) else [values]
    return [as_mapping(value, where) for value in listed]


def same(value: Any, wanted: Any) -> bool:
    """Whether a run's ``value`` of a variable is the value a config names, compared as the run's type: a
    number as a number (the record's 400 or 400.0 is ``N: 400``, a number written as text too), text as
    text (the record's '4', bis_pf_scaling's scene, is ``scene: 4``), true or false only as itself; a run
    without the variable has none."""
    if value is None or (isinstance(value, (float, np.floating)) and math.isnan(value)):
        return False
    if isinstance(value, (bool, np.bool_)) or isinstance(wanted, bool):
        return isinstance(value, (bool, np.bool_)) and isinstance(wanted, bool) and bool(value) == wanted
    if isinstance(value, str):
        return value == str(wanted)
    if isinstance(value, Number):
        try:
            return float(value) == float(wanted)
        except (TypeError, ValueError):
            return False
    return value == wanted


def holds(columns: Mapping[str, Any], wanted: Mapping[str, Any]) -> bool:
    """Whether the condition of a run, as its record's columns (a row, or ``Condition.columns()``), takes
    every value ``wanted`` names (:func:`same`)."""
    return all(same(columns.get(f"{PREFIX}{variable}"), value) for variable, value in wanted.items())


def matching(records: pd.DataFrame, *wanted: Mapping[str, Any]) -> pd.Series:
    """Which rows of ``records`` have a condition that one of ``wanted`` holds for (:func:`holds`)."""
    rows = records[[c for c in records.columns if c.startswith(PREFIX)]].to_dict("records")
    return pd.Series([any(holds(row, w) for w in wanted) for row in rows], index=records.index, dtype=bool)


def written(wanted: Mapping[str, Any]) -> str:
    """A named condition as YAML's flow mapping writes it: ``{scene: exp2_16_targets, N: 400}``."""
    return "{" + ", ".join(f"{variable}: {value}" for variable, value in wanted.items()) + "}"


def instead_of(label: str) -> str:
    """The mapping to write for a condition written as its label, for a message (never read):
    ``scene=x;N=10`` -> ``{scene: x, N: 10}``."""
    return "{" + ", ".join(": ".join(part.split("=", 1)) for part in label.split(";") if part) + "}"
