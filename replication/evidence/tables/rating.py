"""Failed runs rated, beside the paper's rating (bis_pf Table 3)."""

from dataclasses import dataclass

import pandas as pd

from replication.evidence.statistics import proportion
from replication.evidence.tables.table import Compared, Table, TableKind, match
from replication.evidence.verdict import judge_band, stability_bands

class Rating(TableKind):
    """Failed runs per method and condition, the rating they give, and the paper's (bis_pf Table 3)."""

    kind = "rating"

    @dataclass(frozen=True, kw_only=True)
    class Spec(Compared):
        metric: str  # a yes/no outcome per run (failed)

        @property
        def published_metric(self) -> str:
            return self.paper_metric or self.metric

    def build(self, records: pd.DataFrame) -> Table:
        theirs, bands = self.theirs(), stability_bands()
        rows, entries = [], []
        for (method, condition), group in records.groupby(["method", "condition"], sort=False):
            failures, runs = int(group[self.spec.metric].sum()), len(group)
            estimate = proportion(failures, runs)
            hit = match(theirs, method, group.iloc[0], self.spec)
            paper = hit["value"].iloc[0] if len(hit) else ""
            ours = next(name for name, (low, high) in bands.items() if low <= estimate.value <= high)
            verdict = judge_band(paper, failures, runs, bands) if paper else None
            row = {"method": self.label(method), "condition": condition or "-", "runs": runs,
                   "failed runs": failures, "failure rate (Clopper-Pearson 95% CI)": str(estimate), "rating": ours,
                   "paper": paper, "verdict": verdict}
            rows.append(row)
            entries += [self.entry(i, row, verdict, estimate, rating=ours) for i in hit.index]
        return Table(pd.DataFrame(rows), entries)

