"""A relative improvement in %, from paired runs (hspf's 1.8 %)."""

import math
from dataclasses import dataclass

import pandas as pd

from replication.evidence.quantities import quantity
from replication.evidence.statistics import paired_difference
from replication.evidence.tables.table import Compared, Table, TableKind, pair
from replication.evidence.verdict import judge_value
from replication.evidence.settings import INFERENCE

class Improvement(TableKind):
    """A paper's relative claim, 100 (metric[baseline] - metric[method]) / mean metric[baseline] in %,
    from paired runs (both methods filter the same data at a repetition): hspf's 1.8 %."""

    kind = "improvement"

    @dataclass(frozen=True, kw_only=True)
    class Spec(Compared):
        """``method`` against ``baseline`` on ``metric``, judged within ``tolerance_pp`` percentage points."""

        metric: str
        baseline: str
        method: str
        tolerance_pp: float

        @property
        def published_metric(self) -> str:
            return self.paper_metric or self.metric

    def build(self, records: pd.DataFrame) -> Table:
        spec = self.spec
        metric, baseline, method = spec.metric, spec.baseline, spec.method
        paired = pair(records, metric, baseline, method)
        if paired.empty:
            return Table(pd.DataFrame())
        scale = 100.0 / paired["baseline"].mean()
        improvements = (paired["baseline"] - paired["method"]).to_numpy() * scale
        estimate = paired_difference(paired["baseline"], paired["method"]).scaled(scale)
        theirs = self.theirs()
        paper = float(theirs["number"].iloc[0]) if len(theirs) else math.nan
        # equivalence within an absolute margin in percentage points (the config's ``tolerance_pp``): a
        # relative margin of a 1.8 % improvement would be a hair's breadth
        margin = spec.tolerance_pp
        verdict = judge_value(paper, improvements, quantity("improvement"),
                              tolerance=margin / abs(paper) if paper else INFERENCE.tolerance)
        row = {"method": f"{self.label(method)} vs {self.label(baseline)}", "condition": "-",
               "runs": estimate.runs, "estimate": estimate, "ours": estimate.value, "ci_low": estimate.low,
               "ci_high": estimate.high, "interval": estimate.method, "paper": paper, "verdict": verdict}
        return Table(pd.DataFrame([row]), [self.entry(i, row, verdict, estimate) for i in theirs.index])

