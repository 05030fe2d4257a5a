"""Report tables, one module per kind; importing the package registers every kind."""

from replication.evidence.tables import (  # noqa: F401  (each registers its kind)
    attributes, comparison, discrepancy, improvement, leave_one_out, modes, non_inferiority, ranking, rating, summary,
    tuning,
)
from replication.evidence.tables.table import (
    KEYS, TABLE_KINDS, CellResult, Compared, Row, Table, TableKind, TableSpec, cell_value, interval, match, matched,
    number, pair, table_spec, table_specs,
)

__all__ = ["KEYS", "TABLE_KINDS", "CellResult", "Compared", "Row", "Table", "TableKind", "TableSpec", "cell_value",
           "interval", "match", "matched", "number", "pair", "table_spec", "table_specs"]
