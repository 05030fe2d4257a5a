"""A bar every method must clear on every sequence: at least a reference's score, within a margin, and at most
a bound on a count (issue 61's bar for the multi-target pipeline: each particle tracker at least SORT's MOTA
and HOTA, at most 1.5 tracks per person).

For each sequence (the values of ``over``) and each method but the ``reference`` (and the ``others`` shown
for context), each of ``metrics`` is tested for non-inferiority: run r of the method against run r of the
reference on the same video, the method's run meets the bar where its score is at least the reference's less
the ``margin`` (oriented by the metric's direction); each ``most`` metric's run meets it where it is at most the
bound.  The method clears a bar where its median run meets it: the exact sign test (:func:`meets`) of "at least
half the runs fail", one-sided at 5 %.  The median, not the mean: against a deterministic reference (SORT gives
one value on every run) nothing cancels a skewed spread, and the one-sample t on the mean then clears a bar its
mean misses about 11 % of the time under the calibration's lognormal noise at 10 runs (``make calibrate``: the
rows "bar, the t on the mean (rule before)"); the sign test holds 5 % under any noise.  The bar is met when
every test is cleared: an intersection-union test, each at 5 %, so no multiplicity correction is due
(Berger 1982).  Where every run gives one value the test is undefined and clears nothing.  Both rules are
:func:`no_worse` and :func:`at_most`, which the calibration simulates.
"""

from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import stats

from replication.condition import PREFIX
from replication.evidence.inference import sign_test
from replication.evidence.quantities import quantity
from replication.evidence.settings import INFERENCE
from replication.evidence.statistics import Estimate
from replication.evidence.tables.table import Table, TableKind, TableSpec

CLEARED = {True: "yes", False: "no", None: "undefined"}


def meets(ok) -> np.ndarray:
    """The exact one-sided p of "at least half the runs fail" given which runs meet the bar (``ok``, last axis:
    runs): the binomial(n, 1/2) probability of as few failures as seen; NaN where there are no runs."""
    ok = np.asarray(ok, dtype=bool)
    n = ok.shape[-1]
    return stats.binom.cdf(n - ok.sum(axis=-1), n, 0.5) if n else np.full(ok.shape[:-1], np.nan)


def no_worse(ours, theirs, lower_is_better: bool, margin: float) -> np.ndarray:
    """:func:`meets` for "run r of ``ours`` no worse than run r of ``theirs`` by more than ``margin``"; NaN where
    every run of both ties (nothing varies: one observation, not n)."""
    ours, theirs = np.asarray(ours, dtype=float), np.asarray(theirs, dtype=float)
    gain = (theirs - ours if lower_is_better else ours - theirs) + margin
    return np.where(_tied(ours) & _tied(theirs), np.nan, meets(gain >= 0))


def at_most(ours, bound: float) -> np.ndarray:
    """:func:`meets` for "the run is at most ``bound``"; NaN where every run ties."""
    ours = np.asarray(ours, dtype=float)
    return np.where(_tied(ours), np.nan, meets(ours <= bound))


def _tied(values: np.ndarray) -> np.ndarray:
    return (values == values[..., :1]).all(axis=-1)


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
                f"test (the bar is met only when all are), margin {spec.margin:g} against {self.label(spec.reference)}; "
                f"each by the exact sign test of the median run.")
        return Table(frame, note=note)

    def _against(self, sequence, method: str, metric: str, ours: np.ndarray, theirs: np.ndarray) -> dict:
        lower = quantity(metric).lower_is_better
        value = np.median(theirs)
        return self._row(sequence, method, metric, ours, no_worse(ours, theirs, lower, self.spec.margin),
                         f"<= {value:.4g} + {self.spec.margin:g}" if lower else f">= {value:.4g} - {self.spec.margin:g}")

    def _at_most(self, sequence, method: str, metric: str, ours: np.ndarray, bound: float) -> dict:
        return self._row(sequence, method, metric, ours, at_most(ours, bound), f"<= {bound:g}")

    def _row(self, sequence, method: str, metric: str, ours: np.ndarray, p, bar: str) -> dict:
        """A test's row: the median run with its distribution-free interval, the mean beside it, the bar, the
        exact p, and whether the median run clears it."""
        p = float(p)
        median = sign_test(ours)
        return {"sequence": sequence, "method": self.label(method), "metric": metric, "runs": len(ours),
                "median": Estimate(float(median.value), float(median.low), float(median.high), len(ours),
                                   "sign"),
                "mean": float(np.mean(ours)), "bar": f"{bar} (the median run)", "p": p,
                "cleared": CLEARED[None if not np.isfinite(p) else p < INFERENCE.alpha]}
