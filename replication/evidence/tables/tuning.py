"""A tuning sweep and the setting a declared rule picks from it (a free parameter set on other data).

The spec names the ``objective`` (a metric), an optional ``constraint`` (``{metric: m, below: b}``:
only settings whose mean of ``m`` is below ``b`` may be picked), the ``method`` tuned and the ``metrics``
shown.  Rows are the summary's (:mod:`replication.evidence.tables.summary`), best objective first; the rows
of the setting the rule picks (:func:`pick`) are marked, and the note says which it is.  With ``over`` (the
variable naming the sequences, ``scene``) a setting is every condition variable but that one, and the
rule averages its means over the sequences, each weighing the same.  Run it on data the report does not
judge: the pick is then frozen in the experiment that is judged, and this table shows how much the
objective moves with the setting.
"""

from dataclasses import dataclass
from typing import Any

import pandas as pd

from replication.condition import PREFIX
from replication.evidence.aggregate import summarise
from replication.evidence.quantities import quantity
from replication.evidence.tables.summary import Summary
from replication.evidence.tables.table import Table


@dataclass(frozen=True)
class Rule:
    """The declared rule: the best mean ``objective`` of ``method`` (every method's rows if empty) among the
    settings whose mean ``constraint`` metric is below its bound, means averaged over the values of ``over``
    (each weighing the same) where given."""

    objective: str
    method: str
    constraint: dict[str, Any] | None = None
    over: str | None = None

    def pick(self, summaries: dict[str, pd.DataFrame], settings: pd.Series, leaving: Any = None) -> str | None:
        """The setting (a value of ``settings``, aligned with the summaries' rows) the rule picks, the rows of
        ``over == leaving`` left out; None when no setting meets the constraint."""
        def averaged(metric: str) -> pd.Series:
            table = summaries[metric].assign(setting=settings.values)
            tuned = table[table["method"] == self.method] if self.method else table
            if self.over is None:
                return tuned.groupby("setting", sort=False)["mean"].mean()
            tuned = tuned[tuned[PREFIX + self.over] != leaving]
            complete = tuned.groupby("setting")[PREFIX + self.over].nunique() == tuned[PREFIX + self.over].nunique()
            return tuned.groupby("setting", sort=False)["mean"].mean()[complete]

        score = averaged(self.objective)
        if self.constraint:
            score = score[averaged(self.constraint["metric"]).reindex(score.index) < self.constraint["below"]]
        if score.empty:
            return None
        return str(score.idxmin() if quantity(self.objective).lower_is_better else score.idxmax())

    def metrics(self, shown: tuple[str, ...]) -> tuple[str, ...]:
        """The metrics the rule reads (its objective, its constraint's) and then ``shown``, each once."""
        return tuple(dict.fromkeys([self.objective, *([self.constraint["metric"]] if self.constraint else []),
                                    *shown]))

    def said(self, label: str) -> str:
        """The rule in words, the tuned method shown as ``label``."""
        words = f"the best mean {quantity(self.objective).label or self.objective} of {label}"
        if self.constraint:
            words += f" among the settings with mean {self.constraint['metric']} below {self.constraint['below']:g}"
        return words + (", each sequence weighing the same" if self.over else "")

    def settings(self, table: pd.DataFrame) -> pd.Series:
        """Each row's setting: its condition, or with ``over``, 'variable=value; ...' over the condition
        variables but that one."""
        if self.over is None:
            return table["condition"].astype(str)
        variables = [c for c in table.columns if c.startswith(PREFIX) and c != PREFIX + self.over]
        return pd.Series(["; ".join(f"{c[len(PREFIX):]}={v}" for c, v in zip(variables, values)) or "-"
                          for values in table[variables].itertuples(index=False)], index=table.index)


class Tuning(Summary):
    kind = "tuning"

    @dataclass(frozen=True, kw_only=True)
    class Spec(Summary.Spec):
        """The ``objective`` the rule picks by, its ``constraint`` (``{metric: m, below: b}``), the ``method``
        tuned and ``over``, the variable naming the sequences a setting's means are averaged over."""

        objective: str
        metrics: tuple[str, ...] = ()
        constraint: dict[str, Any] | None = None
        method: str = ""
        over: str | None = None

    def build(self, records: pd.DataFrame) -> Table:
        spec = self.spec
        rule = Rule(spec.objective, spec.method, spec.constraint, spec.over)
        metrics = rule.metrics(spec.metrics)
        summaries = {metric: summarise(records, metric) for metric in metrics}
        table = self.frame(summaries)
        settings = rule.settings(summaries[metrics[0]])
        picked = rule.pick(summaries, settings)
        means = pd.Series([e.value for e in table[spec.objective]], index=table.index)
        order = means.sort_values(ascending=quantity(spec.objective).lower_is_better, kind="stable").index
        if spec.constraint:
            metric, below = spec.constraint["metric"], spec.constraint["below"]
            table[f"{metric} < {below:g}"] = ["yes" if e.value < below else "no" for e in table[metric]]
        tuned = summaries[metrics[0]]["method"] == spec.method if spec.method else pd.Series(True, settings.index)
        table["picked"] = ["picked" if s == picked and t else "" for s, t in zip(settings, tuned)]
        table = table.loc[order].reset_index(drop=True)
        said = rule.said(self.label(spec.method))
        note = f"The rule picks {said}: {picked}." if picked is not None else f"No setting meets the rule ({said})."
        return Table(table, note=note)
