"""The point sets' discrepancies (gps_qmcpf Figures 1-3)."""

from dataclasses import dataclass

import pandas as pd

from replication.qmc import discrepancy_table
from replication.evidence.tables.table import Table, TableKind, TableSpec


class Discrepancy(TableKind):
    """gps_qmcpf Figures 1-3's point sets: centred L2 discrepancy of random, Halton and good points."""

    kind = "discrepancy"
    compares = False

    @dataclass(frozen=True, kw_only=True)
    class Spec(TableSpec):
        """``n`` points of each set in each of ``dims`` dimensions, their discrepancy by ``method``."""

        n: int = 400
        dims: tuple[int, ...] = (2, 3, 5)
        method: str = "CD"

    def build(self, records: pd.DataFrame) -> Table:
        spec = self.spec
        return Table(discrepancy_table(n=spec.n, dims=spec.dims, method=spec.method))

