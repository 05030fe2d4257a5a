"""A tuning sweep and the setting a declared rule picks from it (a free parameter set on other data).

The spec names the ``objective`` (a metric), an optional ``constraint`` (``{metric: m, below: b}``:
only settings whose mean of ``m`` is below ``b`` may be picked) and the ``metrics`` shown.  Rows are the
summary's (:mod:`replication.evidence.tables.summary`), best objective first; the row the rule picks
(the best mean objective among the settings that meet the constraint) is marked, and the note says
which it is.  Run it on data the report does not judge: the pick is then frozen in the experiment that
is judged, and this table shows how much the objective moves with the setting.
"""

from dataclasses import dataclass, replace
from typing import Any

import pandas as pd

from replication.evidence.quantities import quantity
from replication.evidence.tables.summary import Summary
from replication.evidence.tables.table import Table


class Tuning(Summary):
    kind = "tuning"

    @dataclass(frozen=True, kw_only=True)
    class Spec(Summary.Spec):
        """The ``objective`` the rule picks by, its ``constraint`` (``{metric: m, below: b}``) and the
        ``method`` tuned (said in the spec; the rows are every method's)."""

        objective: str
        metrics: tuple[str, ...] = ()
        constraint: dict[str, Any] | None = None
        method: str = ""

    def build(self, records: pd.DataFrame) -> Table:
        objective, constraint = self.spec.objective, self.spec.constraint
        metrics = tuple(dict.fromkeys([objective, *([constraint["metric"]] if constraint else []),
                                       *self.spec.metrics]))
        table = Summary(replace(self.spec, metrics=metrics), self.experiment, self.published).build(records).frame
        means = pd.Series([e.value for e in table[objective]], index=table.index)
        table = table.loc[means.sort_values(ascending=quantity(objective).lower_is_better, kind="stable").index]
        table = table.reset_index(drop=True)
        allowed = pd.Series(True, index=table.index)
        if constraint:
            allowed = pd.Series([e.value < constraint["below"] for e in table[constraint["metric"]]], index=table.index)
            table[f"{constraint['metric']} < {constraint['below']:g}"] = ["yes" if a else "no" for a in allowed]
        picked = allowed.idxmax() if allowed.any() else None
        table["picked"] = ["picked" if i == picked else "" for i in table.index]
        rule = f"the best mean {quantity(objective).label or objective}" + (
            f" among settings with mean {constraint['metric']} below {constraint['below']:g}" if constraint else "")
        note = (f"The rule picks {rule}: {table.at[picked, 'condition']}." if picked is not None
                else f"No setting meets the rule ({rule}).")
        return Table(table, note=note)
