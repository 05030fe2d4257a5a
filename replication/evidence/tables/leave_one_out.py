"""A tuning rule checked on data it did not see: each sequence left out in turn.

The sweep's runs cover every setting on every tuning sequence.  For each sequence left out, the
declared rule (:class:`~replication.evidence.tables.tuning.Rule`: the best ``objective`` of the
tuned ``method``, averaged over the *other* sequences, each weighing the same, among the settings whose
``constraint`` metric averages below its bound there) picks a setting; the rows then show every
method at that setting on the sequence left out, beside the ``reference`` (a method without the
setting, SORT) on it.  That is the estimate of how the pipeline, tuned by the rule, does on a
sequence of a user's own, and the spread over the left-out sequences is its variability.
"""

from dataclasses import dataclass
from typing import Any

import pandas as pd

from replication.condition import PREFIX
from replication.evidence.aggregate import summarise
from replication.evidence.quantities import quantity
from replication.evidence.statistics import Estimate
from replication.evidence.tables.table import Table, TableKind, TableSpec
from replication.evidence.tables.tuning import Rule


class LeaveOneOut(TableKind):
    kind = "leave_one_out"
    compares = False

    @dataclass(frozen=True, kw_only=True)
    class Spec(TableSpec):
        """The rule (``objective`` of ``method``, ``constraint`` ``{metric: m, below: b}``), the variable
        naming the sequences (``over``), the ``reference`` shown beside, and the ``metrics`` shown."""

        objective: str
        method: str
        reference: str
        metrics: tuple[str, ...]
        constraint: dict[str, Any] | None = None
        over: str = "scene"

    def build(self, records: pd.DataFrame) -> Table:
        spec, over = self.spec, PREFIX + self.spec.over
        rule = Rule(spec.objective, spec.method, spec.constraint, spec.over)
        summaries = {metric: summarise(records, metric) for metric in rule.metrics(spec.metrics)}
        first = summaries[spec.objective]
        settings = rule.settings(first)
        sequences = list(dict.fromkeys(first[over]))
        rows, picks = [], {}
        for left_out in sequences:
            picks[left_out] = picked = rule.pick(summaries, settings, leaving=left_out)
            for method in dict.fromkeys(first["method"]):
                at = (first["method"] == method) & (first[over] == left_out)
                if method != spec.reference:
                    at &= settings == picked
                if picked is None or not at.any():
                    continue
                index = at.idxmax()
                rows.append({"left out": left_out, "method": self.label(method),
                             "setting": "-" if method == spec.reference else picked,
                             "runs": int(first.at[index, "runs"]),
                             **{m: Estimate(*summaries[m].loc[index, ["mean", "ci_low", "ci_high", "runs"]], "")
                                for m in spec.metrics}})
        shown = ", ".join(f"{left_out}: {picked or 'none meets the rule'}" for left_out, picked in picks.items())
        note = (f"Each of the {len(sequences)} sequences is left out in turn; the rule "
                f"({rule.said(self.label(spec.method))}) picks on the others: {shown}." + self._spread(rows))
        return Table(pd.DataFrame(rows), note=note)

    def _spread(self, rows: list[dict]) -> str:
        """' On the sequence left out, <objective> ranges ...': what a user's own video may give, per method."""
        objective = self.spec.objective
        if objective not in self.spec.metrics or not rows:
            return ""
        frame = pd.DataFrame(rows)
        ranges = [f"{method} {min(e.value for e in group[objective]):.3g} to {max(e.value for e in group[objective]):.3g}"
                  for method, group in frame.groupby("method", sort=False)]
        name = quantity(objective).label or objective
        return f" On the sequence left out, {name} ranges over the sequences: {'; '.join(ranges)}."
