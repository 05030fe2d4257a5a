"""The point sets' discrepancies (gps_qmcpf Figures 1-3)."""

import pandas as pd

from replication.qmc import discrepancy_table
from replication.evidence.tables.table import Table, TableKind

class Discrepancy(TableKind):
    """gps_qmcpf Figures 1-3's point sets: centred L2 discrepancy of random, Halton and good points."""

    kind = "discrepancy"
    compares = False

    def build(self, records: pd.DataFrame) -> Table:
        spec = self.spec
        return Table(discrepancy_table(n=int(spec.get("n", 400)), dims=tuple(spec.get("dims", (2, 3, 5))),
                                       method=spec.get("method", "CD")))

