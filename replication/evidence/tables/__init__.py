"""Report tables, one module per kind; importing the package registers every kind."""

from replication.evidence.tables import (  # noqa: F401  (each registers its kind)
    attributes, comparison, discrepancy, improvement, modes, ranking, rating, summary, tuning,
)
from replication.evidence.tables.table import (
    KEYS, CellResult, Row, Table, TableKind, cell_value, interval, match, matched, number, pair,
)

__all__ = ["KEYS", "CellResult", "Row", "Table", "TableKind", "cell_value", "interval", "match", "matched", "number",
           "pair"]
