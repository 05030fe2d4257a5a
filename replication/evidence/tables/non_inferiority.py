"""A bar every method must clear on every sequence: at least a reference's score, within a margin, and at most
a bound on a count (issue 61's bar for the multi-target pipeline: each particle tracker at least SORT's MOTA
and HOTA, at most 1.5 tracks per person).

For each sequence (the values of ``over``) and each method but the ``reference`` (and the ``others`` shown
for context), each of ``metrics`` is tested for non-inferiority: run r of the method against run r of the
reference on the same video, the gain (method minus reference, oriented by the metric's direction) plus the
``margin``, by :func:`~replication.evidence.comparisons.order_test` (the paired t of the claims, whose error
rates the calibration simulates); the method clears it where the one-sided p is below 5 %.  Against a
deterministic reference (SORT gives one value on every run) that is the one-sample t against its value.
Each ``most`` metric clears its bound where the one-sided 95 % upper bound of its mean is at most the bound.
The bar is met when every test is cleared: an intersection-union test, each at 5 %, so no multiplicity
correction is due (Berger 1982).  Where every run gives one value the test is undefined and clears nothing.
"""

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from replication.condition import PREFIX
from replication.evidence.comparisons import order_test
from replication.evidence.inference import mean_test
from replication.evidence.quantities import quantity
from replication.evidence.settings import INFERENCE
from replication.evidence.statistics import Estimate
from replication.evidence.tables.table import Table, TableKind, TableSpec

CLEARED = {True: "yes", False: "no", None: "undefined"}


class NonInferiority(TableKind):
    kind = "non_inferiority"
    compares = False

    @dataclass(frozen=True, kw_only=True)
    class Spec(TableSpec):
        """``metrics`` tested against the ``reference`` at ``margin``; ``most``: {metric: bound}; ``others``:
        methods shown for context, never held to the bar; ``over``: the variable naming the sequences."""

        reference: str
        metrics: tuple[str, ...]
        margin: float
        most: dict[str, float] = field(default_factory=dict)
        others: tuple[str, ...] = ()
        over: str = "scene"

    def build(self, records: pd.DataFrame) -> Table:
        spec, over, rows = self.spec, PREFIX + self.spec.over, []
        for sequence, runs in records.groupby(over, sort=False):
            reference = runs[runs["method"] == spec.reference].set_index("repetition")
            for method, own in runs.groupby("method", sort=False):
                if method == spec.reference or method in spec.others:
                    continue
                own = own.set_index("repetition")
                paired = own.index.intersection(reference.index)
                for metric in spec.metrics:
                    rows.append(self._against(sequence, method, metric, own.loc[paired, metric].to_numpy(float),
                                              reference.loc[paired, metric].to_numpy(float)))
                for metric, bound in spec.most.items():
                    rows.append(self._at_most(sequence, method, metric, own[metric].to_numpy(float), bound))
        frame = pd.DataFrame(rows)
        met = frame["cleared"].eq(CLEARED[True]).all() if len(frame) else False
        note = (f"{'Every' if met else 'Not every'} test is cleared: one-sided 5 % each, an intersection-union "
                f"test (the bar is met only when all are), margin {spec.margin:g} against {self.label(spec.reference)}.")
        return Table(frame, note=note)

    def _against(self, sequence, method: str, metric: str, ours: np.ndarray, theirs: np.ndarray) -> dict:
        kind = quantity(metric)
        tested = order_test(ours, theirs, kind.lower_is_better, allowed=self.spec.margin)
        p = float(tested.p_for)
        cleared = None if not np.isfinite(p) else p < INFERENCE.alpha
        mean = mean_test(ours)
        return {"sequence": sequence, "method": self.label(method), "metric": metric, "runs": len(ours),
                "mean": Estimate(float(mean.value), float(mean.low), float(mean.high), len(ours), "t"),
                "bar": f">= {np.mean(theirs):.4g} - {self.spec.margin:g}" if not kind.lower_is_better
                else f"<= {np.mean(theirs):.4g} + {self.spec.margin:g}",
                "p": p, "cleared": CLEARED[cleared]}

    def _at_most(self, sequence, method: str, metric: str, ours: np.ndarray, bound: float) -> dict:
        mean = mean_test(ours, bound)  # its interval is the mean's whatever the reference; p_below: mean < bound
        high = float(mean.high)
        cleared = None if not np.isfinite(high) else high <= bound
        return {"sequence": sequence, "method": self.label(method), "metric": metric, "runs": len(ours),
                "mean": Estimate(float(mean.value), float(mean.low), high, len(ours), "t"),
                "bar": f"<= {bound:g} (one-sided 95 % upper bound)", "p": float(mean.p_below),
                "cleared": CLEARED[cleared]}
