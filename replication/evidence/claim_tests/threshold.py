"""``threshold``: a statistic against a bound; ``growth``: a power law's exponent against a bound;
``pareto``: a setting no other beats on both metrics."""

from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from replication.condition import values_of
from replication.evidence.checks import Check, finite
from replication.evidence.inference import mean_test, proportion_test, said_p, sign_test
from replication.evidence.quantities import quantity
from replication.evidence.settings import INFERENCE
from replication.evidence.statistics import Estimate
from replication.evidence.trends import dominance, log_log_slope
from replication.evidence.verdict import Outcome, Verdict, too_few
from replication.evidence.claim_tests.base import ClaimSpec, ClaimTest, Measured


class Threshold(ClaimTest):
    """``method`` at ``condition`` reaches a bound, ``at_least`` or ``at_most``: the exact sign test of its
    median (``statistic: median``), the exact binomial test of a yes/no rate, else the t-test of its mean,
    one-sided each way.  A check at each of the method's conditions that ``condition`` picks (:func:`named`;
    none: each of them), named in the check where it picks several."""

    name = "threshold"

    @dataclass(frozen=True, kw_only=True)
    class Spec(Measured):
        method: str
        at_least: float | None = None
        at_most: float | None = None
        condition: Any = None
        statistic: str = "mean"
        machine: str = ""  # "this": a time measured on this machine is tested
        unit: str = ""

        @property
        def naming(self) -> tuple:
            return (self.conditions, self.condition)

    def checks(self, records, tables):
        ours = records[records["method"] == self.spec.method]
        labels = self.conditions(ours)
        return [check for label in labels
                for check in self.at(ours[ours["condition"] == label], f" at {label}" if len(labels) > 1 else "")]

    def at(self, chosen: pd.DataFrame, where: str) -> list[Check]:
        """The check on the runs of one condition, ``chosen`` (``where``: the condition, said after the method)."""
        spec = self.spec
        metric = spec.metric
        chosen = chosen[np.isfinite(chosen[metric].astype(float))]
        if chosen.empty:
            return []
        kind = quantity(metric)
        values = chosen[metric].to_numpy(float)
        bound, above = (spec.at_least, True) if spec.at_least is not None else (spec.at_most, False)
        if kind.machine_dependent and spec.machine != "this":  # a time measured on another machine
            return [_elsewhere(spec, values, bound, chosen, where)]
        if kind.proportion:
            test = proportion_test(int(round(values.sum() / kind.high)), len(values), bound / kind.high)
            factor = kind.high
        else:
            test = (sign_test if spec.statistic == "median" else mean_test)(values, bound)
            factor = 1.0
        shown = Estimate(float(test.value) * factor, float(test.low) * factor, float(test.high) * factor,
                         len(values), test.method, 1 - 2 * INFERENCE.alpha)
        what = f"{spec.method}{where} {spec.statistic} {metric} {'>=' if above else '<='} {bound:g}"
        p_for, p_against = (test.p_above, test.p_below) if above else (test.p_below, test.p_above)
        verdict = too_few(len(values)) or threshold_verdict(finite(p_for), finite(p_against))
        return [Check(what, verdict, shown, spec.unit, float(bound),
                      dict(zip(chosen["repetition"].astype(int), values)), paper=float(bound),
                      timed=kind.machine_dependent)]


def _elsewhere(spec: "Threshold.Spec", values: np.ndarray, bound: float, chosen: pd.DataFrame, where: str = "") -> Check:
    """A bound on a time or frame rate that the paper measured on its own machine: not testable here
    (docs/statistics.md, "Times"), with our median over theirs shown (``where``: the condition, as a
    threshold's check says it)."""
    ours = float(np.median(values))
    what = f"{spec.method}{where} median {spec.metric} against the paper's {bound:g} (its machine)"
    why = f"a time measured on another machine is not testable; ours / theirs = {ours / bound:.3g}"
    return Check(what, Verdict(Outcome.NOT_TESTABLE, why), None, spec.unit, float(bound),
                 dict(zip(chosen["repetition"].astype(int), values)), paper=float(bound), timed=True)


def threshold_verdict(p_for: float | None, p_against: float | None, against: str = "the other side of the bound",
                       then: str = "") -> Verdict:
    """A one-sided test each way: its verdict before the reading's Holm (``then``: said after the why)."""
    if p_for is None and p_against is None:
        return Verdict(Outcome.NOT_TESTABLE, f"every run ties: no test{then}")
    if p_for is not None and p_for < INFERENCE.alpha:
        return Verdict(Outcome.REPRODUCED, f"{said_p(p_for)}{then}", p_for, p_against)
    if p_against is not None and p_against < INFERENCE.alpha:
        return Verdict(Outcome.NOT_REPRODUCED, f"{against}, {said_p(p_against)}{then}", p_for, p_against)
    return Verdict(Outcome.INCONCLUSIVE, f"{said_p(p_for)} for, {said_p(p_against)} against{then}", p_for,
                   p_against)


class Growth(ClaimTest):
    """``method``'s ``metric`` grows with the condition variable ``x`` (its values read as numbers) no faster
    than x^``at_most``: the log-log slope over every run (:func:`~replication.evidence.trends.log_log_slope`),
    reproduced where its upper bound lies below ``at_most``, not reproduced where its lower bound lies above."""

    name = "growth"

    @dataclass(frozen=True, kw_only=True)
    class Spec(Measured):
        method: str
        x: str
        at_most: float

    def checks(self, records, tables):
        spec = self.spec
        runs = records[records["method"] == spec.method]
        x = pd.to_numeric(values_of(runs, spec.x), errors="coerce").to_numpy(float)
        values = runs[spec.metric].to_numpy(float)
        kept = np.isfinite(x) & np.isfinite(values) & (x > 0) & (values > 0)
        if kept.sum() < INFERENCE.min_runs:
            return [Check(f"{spec.method} {spec.metric} against {spec.x}", too_few(int(kept.sum())))]
        slope = log_log_slope(x[kept], values[kept], spec.at_most)
        what = f"{spec.method}: growth exponent of {spec.metric} in {spec.x} ({len(set(x[kept]))} values)"
        verdict = threshold_verdict(finite(slope.p_below), finite(slope.p_above), f"faster than {spec.x}^{spec.at_most:g}")
        shown = Estimate(float(slope.value), float(slope.low), float(slope.high), slope.points,
                         "least squares on logs, t", 1 - 2 * INFERENCE.growth_alpha)
        return [Check(what, verdict, shown, reference=float(spec.at_most), paper=float(spec.at_most),
                      timed=quantity(spec.metric).machine_dependent)]


class Pareto(ClaimTest):
    """``method`` at the ``chosen`` condition (a mapping, :func:`named`) keeps both ``metrics`` (lower is better)
    small: against every other condition of the method, one check (:func:`~replication.evidence.trends.dominance`,
    paired by run): reproduced where, against each, the chosen setting is better on at least one metric; not
    reproduced where some other setting is better on both, after Holm."""

    name = "pareto"

    @dataclass(frozen=True, kw_only=True)
    class Spec(ClaimSpec):
        method: str
        metrics: list[str]
        chosen: Any = None

        @property
        def reads(self) -> tuple[str, ...]:
            return tuple(self.metrics)

        @property
        def naming(self) -> tuple:
            return (self.conditions, self.chosen)

    def checks(self, records, tables):
        spec, metrics = self.spec, list(self.spec.metrics)
        runs = records[records["method"] == spec.method]
        keyed = runs.set_index(["data_condition", "repetition"])
        labels = self.conditions(runs)  # the chosen one (each, where the mapping picks several)
        found = []
        for chosen_label in labels:
            chosen = keyed[keyed["condition"] == chosen_label][metrics]
            for other, rows in keyed[~keyed["condition"].isin(labels)].groupby("condition", sort=False):
                both = chosen.merge(rows[metrics], left_index=True, right_index=True, suffixes=("", " (other)")).dropna()
                if len(both) < INFERENCE.min_runs:
                    continue
                tested = dominance(both[metrics].to_numpy(), both[[f"{m} (other)" for m in metrics]].to_numpy())
                gains = ", ".join(f"{m} {g:+.3g}" for m, g in zip(metrics, tested.gains))
                verdict = threshold_verdict(finite(tested.p_for), finite(tested.p_against),
                                             f"{other} is better on both")
                found.append(Check(f"{chosen_label} against {other} (the other minus the chosen: {gains})", verdict,
                                   timed=any(quantity(m).machine_dependent for m in metrics)))
        return found
