"""Ours only: each metric's mean and 95% interval per method and condition."""

from dataclasses import dataclass

import pandas as pd

from replication.evidence.aggregate import summarise
from replication.evidence.statistics import Estimate
from replication.evidence.tables.table import Table, TableKind, TableSpec


class Summary(TableKind):
    """Ours only: one row per method and condition, one column per metric: its mean and 95% interval
    (shown 'mean [low, high]'; in the CSV as the metric's column and its ``_low`` and ``_high``)."""

    kind = "summary"
    compares = False

    @dataclass(frozen=True, kw_only=True)
    class Spec(TableSpec):
        metrics: tuple[str, ...]

    def build(self, records: pd.DataFrame) -> Table:
        return Table(self.frame({metric: summarise(records, metric) for metric in self.spec.metrics}))

    def frame(self, columns: dict[str, pd.DataFrame]) -> pd.DataFrame:
        """The table's rows from each metric's :func:`summarise` (``columns``, in the order shown)."""
        first = next(iter(columns.values()))
        table = pd.DataFrame({"method": [self.label(m) for m in first["method"]],
                              "condition": [c or "-" for c in first["condition"]], "runs": first["runs"]})
        for metric, summary in columns.items():
            table[metric] = [Estimate(*values, "") for values in
                             zip(summary["mean"], summary["ci_low"], summary["ci_high"], summary["runs"])]
        return table

