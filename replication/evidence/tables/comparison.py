"""Ours beside the paper's number, judged: the kind of Tables 1-4 of most papers."""

import math
from dataclasses import dataclass, replace

import pandas as pd

from replication.evidence.aggregate import summarise
from replication.evidence.quantities import quantity
from replication.evidence.statistics import Estimate, paired_difference
from replication.evidence.named_conditions import matching
from replication.evidence.tables.table import SENSITIVITY, Compared, Table, TableKind, match, matched
from replication.evidence.verdict import Verdict, judge_value
from replication.evidence.settings import INFERENCE

FLOOR_FILTER = "point_mass"  # the Bayes floor: the point-mass filter


class Comparison(TableKind):
    """Ours (a statistic with its 95% interval) beside the paper's number, judged (Tables 1-4 of most papers)."""

    kind = "comparison"

    @dataclass(frozen=True, kw_only=True)
    class Spec(Compared):
        """``metric``'s ``statistic`` over runs (times ``scale``: a share in %), judged against the paper's
        number at the equivalence ``tolerance`` (default: the settings'), with the runs behind the paper's
        number (``paper_runs``; ``paper_runs_stated: false`` where the paper does not say them)."""

        metric: str
        statistic: str = "mean"
        scale: float = 1.0
        tolerance: float | None = None
        paper_runs: int | None = None
        paper_runs_stated: bool = True
        show_variance: bool = False

        @property
        def published_metric(self) -> str:
            return self.paper_metric or self.metric

    def build(self, records: pd.DataFrame) -> Table:
        spec, methods = self.spec, self.experiment["methods"]
        metric, paper_metric = spec.metric, spec.published_metric
        kind = quantity(paper_metric if quantity(paper_metric).machine_dependent else metric)
        kind = kind.scaled(spec.scale)
        ours = summarise(records, metric, spec.scale, spec.statistic)
        ours = ours[ours["runs"] > 0]
        floor_runs, excess = None, {}
        if metric == "rmse":
            floor = [m for m in methods if methods[m]["filter"] == FLOOR_FILTER]
            floors = ours[ours["method"].isin(floor)]
            # the floor at the condition where it is lowest: the weakest evidence that a value lies below it
            floor_runs = floors.loc[floors["mean"].idxmin(), "values"] if len(floors) else None
            excess = excess_over_floor(records, floor)
        if spec.match:  # the conditions the paper's table covers
            ours = ours[matching(ours, *(condition for condition, _ in matched(spec)))]
        theirs = self.theirs()
        rows, entries = [], []
        for _, row in ours.iterrows():
            estimate = Estimate(row["mean"], row["ci_low"], row["ci_high"], row["runs"], row["interval"])
            hit = match(theirs, row["method"], row, spec)
            paper = float(hit["number"].iloc[0]) if len(hit) else math.nan
            def judged(tolerance: float) -> Verdict | None:
                return judge_value(paper, row["values"], kind, spec.statistic, spec.paper_runs, floor_runs, tolerance)

            verdict = judged(INFERENCE.tolerance if spec.tolerance is None else spec.tolerance)
            shown = {"method": self.label(row["method"]), "condition": row["condition"] or "-",
                     "runs": row["runs"], "estimate": estimate, "ours": row["mean"], "ci_low": row["ci_low"],
                     "ci_high": row["ci_high"], "interval": row["interval"]}
            if excess:
                shown["excess over the floor (paired, 95% CI)"] = str(
                    excess.get((row["method"], row["condition"]), ""))
            if spec.show_variance:
                shown["variance over runs"] = row["variance"]
            shown.update(paper=paper, verdict=verdict)
            rows.append(shown)
            moved = {f"{t:g}": judged(t).outcome for t in SENSITIVITY} if verdict else {}
            entries += [replace(self.entry(i, shown, verdict, estimate), at_tolerance=moved) for i in hit.index]
        return Table(pd.DataFrame(rows), entries)


def excess_over_floor(records: pd.DataFrame, floor_methods: list[str]) -> dict:
    """Paired RMSE minus the point-mass filter's RMSE on the same trajectory: an Estimate per (method,
    condition).  Every method filters the same data at a repetition, so the paired difference isolates
    the filter's own error from the run-to-run spread."""
    floor = records[records["method"].isin(floor_methods)][["data_condition", "repetition", "rmse"]]
    if floor.empty:
        return {}
    paired = records.merge(floor, on=["data_condition", "repetition"], suffixes=("", "_floor"))
    paired = paired[~paired["method"].isin(floor_methods)]
    return {key: paired_difference(group["rmse"], group["rmse_floor"])
            for key, group in paired.groupby(["method", "condition"], sort=False)}

