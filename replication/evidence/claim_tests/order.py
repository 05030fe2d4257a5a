"""``order``: methods in the claimed order by paired differences on common random numbers; ``equal_cost``:
the same with the baseline given the method's budget."""

import itertools
import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import pandas as pd

from replication.evidence.checks import Check, finite
from replication.evidence.comparisons import Effect, OrderTest, order_test
from replication.evidence.criteria import Replication
from replication.evidence.inference import said_p
from replication.evidence.original import runs_behind
from replication.evidence.published import cells as published_cells
from replication.evidence.quantities import quantity
from replication.evidence.settings import INFERENCE
from replication.evidence.statistics import Estimate
from replication.evidence.tables import match, pair, table_specs
from replication.evidence.verdict import Outcome, Verdict, too_few
from replication.evidence.claim_tests.base import ClaimTest, Measured, listed


WORK = "evaluations_per_step"  # the work counted beside a time (replication.smc.work)


class Order(ClaimTest):
    """``order: [A, [B, C], D]``: A beats B and C, each of which beats D, on ``metric``, at each condition.

    Each pair is a check on the runs that filtered the same data and where both methods' metric is defined
    (:func:`~replication.evidence.comparisons.order_test`): Student's paired
    t-test (McNemar's exact test for yes/no outcomes) in the claimed direction,
    and, where ``size:`` names the paper's table (or a user's claim quotes its
    numbers, ``size: {quoted: {A: 4.1, B: 4.5}}``), the paper's own gap between
    the two (a difference, or with ``kind: ratio`` a ratio) against ours.
    ``tolerance`` (a fraction of the beaten method's mean) turns "better" into
    "no worse than by more than that" (a claim of equal cost, say).
    """

    name = "order"

    @dataclass(frozen=True, kw_only=True)
    class Spec(Measured):
        order: list
        scale: float = 1.0
        unit: str = ""
        tolerance: float = 0.0
        size: dict[str, Any] | None = None

        @property
        def sized(self) -> bool:
            return self.size is not None

    def checks(self, records, tables):
        metric, scale = self.spec.metric, self.spec.scale
        kind = quantity(metric)
        unit = self.spec.unit
        groups = [listed(g) for g in self.spec.order]
        found = []
        for condition in self.conditions(records):
            for better, worse in zip(groups, groups[1:]):
                for a, b in itertools.product(better, worse):
                    paired = pair(records, metric, b, a, condition)
                    paired = paired[np.isfinite(paired[["baseline", "method"]]).all(axis=1)]  # both defined
                    what = f"{a} - {b}" + (f" at {condition}" if condition else "")
                    if paired.empty:
                        continue
                    allowed = self.spec.tolerance * abs(paired["baseline"].mean())
                    better, worse = paired["method"].to_numpy(), paired["baseline"].to_numpy()
                    there = records.iloc[np.flatnonzero(records["condition"] == condition)[0]]  # a run's row
                    paper = self.effect(a, b, there, len(paired))
                    verdict, difference, replication = _order_check(better, worse, kind, scale, allowed, paper)
                    # the line the difference better - worse is tested against: worse by at most the allowance
                    line = allowed * scale * (1 if kind.lower_is_better else -1)
                    if allowed and verdict.outcome is not Outcome.NOT_TESTABLE:
                        verdict = _allowing(verdict, difference, line, paired["baseline"].mean() * scale, unit)
                    per_run = dict(zip(paired["repetition"].astype(int), (better - worse) * scale))
                    work = _work(records, (a, b), condition) if kind.machine_dependent else ""  # beside a time
                    found.append(Check(what, verdict, difference, unit, line, per_run, work,
                                       _shown_gap(paper), kind.machine_dependent, replication))
        return found

    def effect(self, better: str, worse: str, ours: pd.Series, runs: int) -> Effect | None:
        """The paper's numbers for the pair at our condition (``ours``: a run's record there), matched with its
        cells as our table named by ``size.table`` matches them (a list: the first holding both; None where
        ``size`` names none, or a number is missing), with the runs behind them by :func:`~replication.evidence.original.paper_runs` (``runs``:
        ours): the table's ``paper_runs`` where the paper states them (a user's ``size.runs``)."""
        size = self.spec.size
        if size and "quoted" in size:  # a user's claim quoting its own numbers ({method: number}), no table
            quoted = size["quoted"]
            if better not in quoted or worse not in quoted:
                return None
            behind = runs_behind(runs, size.get("runs"), [str(v) for v in quoted.values()], self.spec.metric,
                                 self.spec.scale)
            return Effect(float(quoted[better]), float(quoted[worse]), behind, size.get("kind", "difference"))
        if not size or self.published is None:
            return None
        specs = {table.name: table for table in table_specs(self.experiment)}
        for name in listed(size["table"]):  # the first of the named tables that holds both numbers here
            table = specs[name]
            theirs = published_cells(self.published, self.experiment["paper"], table.paper_table,
                                     table.published_metric)
            methods = size.get("methods", {})
            values = [match(theirs, str(methods.get(m, m)), ours, table)["number"] for m in (better, worse)]
            if all(len(v) == 1 and np.isfinite(v.iloc[0]) for v in values):
                break
        else:
            return None
        stated = table.paper_runs if table.paper_runs_stated else None
        printed = list(theirs.loc[theirs["number"].notna(), "value"])  # as printed: their precision
        behind = runs_behind(runs, stated, printed, table.metric, table.scale)
        return Effect(float(values[0].iloc[0]), float(values[1].iloc[0]), behind, size.get("kind", "difference"))


class EqualCost(ClaimTest):
    """Each ``method`` beats each ``baseline`` (one name or a list of either) on ``metric`` with the baseline
    given at least the method's budget, at each of the method's ``conditions``: of the baseline's conditions
    on the same data (an N sweep on the same scene), the cheapest whose ``cost`` over runs (the mean of a
    count such as ``evaluations_per_step``; the median of a time) reaches the method's there; paired by run on
    the same data, tested as ``order`` tests a pair.  A claim made at equal N, read at equal cost.  A baseline
    that already spends more at the paper's N is compared there (it is given more than the budget, which can
    only favour it).  No baseline condition reaching the budget: not testable, and said."""

    name = "equal_cost"

    @dataclass(frozen=True, kw_only=True)
    class Spec(Measured):
        cost: str
        method: str | list[str]
        baseline: str | list[str]
        scale: float = 1.0
        unit: str = ""

        @property
        def reads(self) -> tuple[str, ...]:
            return (self.metric, self.cost)

        @property
        def basis(self) -> str:
            return quantity(self.cost).label or self.cost

    def checks(self, records, tables):
        metric, cost = self.spec.metric, self.spec.cost
        pairs = itertools.product(listed(self.spec.method), listed(self.spec.baseline))
        return [check for method, baseline in pairs for check in self.pair(records, metric, cost, method, baseline)]

    def pair(self, records: pd.DataFrame, metric: str, cost: str, method: str, baseline: str) -> list[Check]:
        statistic = "median" if quantity(cost).machine_dependent else "mean"
        found = []
        for condition in self.conditions(records[records["method"] == method]):
            ours = records[(records["method"] == method) & (records["condition"] == condition)]
            theirs = records[(records["method"] == baseline)  # on the same data (scene) as ours
                             & records["data_condition"].isin(ours["data_condition"].unique())]
            if ours.empty or theirs.empty:
                continue
            spent = theirs.groupby("condition")[cost].agg(statistic).sort_values()
            budget = float(ours[cost].agg(statistic))
            at = f" at {condition}" if condition else ""
            what = f"{method}{at} - {baseline} at equal {self.spec.basis}"
            reaching = spent[spent >= budget]
            if reaching.empty:
                why = f"no condition of {baseline} reaches the budget (at most {spent.max():.4g})"
                found.append(Check(what, Verdict(Outcome.NOT_TESTABLE, why), detail=f"budget {budget:.4g}"))
                continue
            chosen = reaching.index[0]
            paired = pair(records, metric, baseline, method, condition, baseline_condition=chosen)
            paired = paired[np.isfinite(paired[["baseline", "method"]]).all(axis=1)]  # both defined
            better, worse = paired["method"].to_numpy(), paired["baseline"].to_numpy()
            scale = self.spec.scale
            verdict, difference, _ = _order_check(better, worse, quantity(metric), scale, 0.0, None)
            per_run = dict(zip(paired["repetition"].astype(int), (better - worse) * scale))
            spends = f"budget {budget:.4g}; {baseline} at {chosen} spends {spent[chosen]:.4g}"
            found.append(Check(what, verdict, difference, self.spec.unit, 0.0, per_run, spends,
                               timed=quantity(cost).machine_dependent))  # the baseline's N is chosen by time
        return found


def _work(records: pd.DataFrame, methods: tuple[str, ...], condition: str) -> str:
    """The likelihood evaluations per step each of ``methods`` spends at ``condition`` (mean over runs), shown
    beside a comparison of times, so a slower code can be told from more work ("" where the runs count none)."""
    if WORK not in records:
        return ""
    at = records[records["condition"] == condition] if condition else records
    spent = [at.loc[at["method"] == m, WORK].mean() for m in methods]
    if not all(np.isfinite(spent)):
        return ""
    return f"{quantity(WORK).label}: " + ", ".join(f"{m} {w:.4g}" for m, w in zip(methods, spent))


def _order_check(better: np.ndarray, worse: np.ndarray, kind, scale: float, allowed: float,
                 paper: Effect | None) -> tuple[Verdict, Estimate, Replication | None]:
    """One pair's verdict (before the reading's Holm), the paired difference better - worse shown with
    it, in the claim's units (``scale``): the raw difference, the margin ``allowed`` in the claim's favour
    (in the runs' units) tested but not shown in it; and where the paper quotes a size that favours the
    claim and the runs test it, the two effects for the replication criteria."""
    runs = len(better)
    binary = kind.proportion
    unit = kind.high * scale if binary else scale  # yes/no outcomes are tested as 0 or 1
    # the paper's numbers are in the claim's units (a share printed in %, scale 100): tested in the runs' own
    as_tested = replace(paper, better=paper.better / unit, worse=paper.worse / unit) if paper else None
    tested = order_test(better * scale / unit, worse * scale / unit, kind.lower_is_better, binary,
                        allowed * scale / unit, as_tested)
    difference = _shown(tested, unit * (-1 if kind.lower_is_better else 1), runs, allowed * scale / unit,
                        (kind.high - kind.low) * scale)
    few = too_few(runs)
    if few:
        return few, difference, None
    if tested.tied:
        return Verdict(Outcome.NOT_TESTABLE, _tied(float(better[0]), runs, kind, scale)), difference, None
    replication = tested.replication.single() if tested.replication is not None else None
    return _order_verdict(tested, paper, unit, binary), difference, replication


def _tied(value: float, runs: int, kind, scale: float) -> str:
    """Why a pair whose every run of both methods gives one ``value`` (a floor, a ceiling) decides nothing."""
    where = "at the floor" if value == kind.low else "at the ceiling" if value == kind.high else "at one value"
    said = f"{value * runs:.0f} of {runs}" if kind.proportion else f"{value * scale:.4g}"
    return f"every run of both methods {where} ({said}): the scene decides nothing about the paper here"


def _shown_gap(paper: Effect | None) -> float | None:
    """The paper's gap better - worse, in the claim's units as ours is shown, where it quotes one as a difference."""
    return None if paper is None or paper.kind != "difference" else paper.better - paper.worse


def _shown(tested: OrderTest, factor: float, runs: int, allowed: float, span: float) -> Estimate:
    """A pair's gain as the difference better - worse in the claim's units (``factor`` flips the sign where
    lower is better); ``allowed``, the margin the test added to the gain in the claim's favour, taken back out:
    the raw difference.  Each end of its interval is the one-sided bound of the test it decides: the
    direction's (95 %), and on the paper's side the size test's where it is tested in these units (ours with
    the paper's noise, one-sided at the size test's level); within the differences the metric's range
    allows (+-``span``)."""
    test, bound = tested.gain, tested.bound
    ends = np.clip(sorted([(float(test.low) - allowed) * factor, (float(bound.high) - allowed) * factor]), -span,
                   span)
    sized = bound is not test
    return Estimate((float(test.value) - allowed) * factor, *map(float, ends), runs,
                    f"paired {test.method}" + (f"; its end on the paper's side {bound.method}" if sized else ""),
                    1 - INFERENCE.alpha - INFERENCE.size_alpha if sized else 1 - 2 * INFERENCE.alpha)


def _allowing(verdict: Verdict, difference: Estimate, line: float, baseline: float, unit: str) -> Verdict:
    """A check's verdict with the raw difference and the allowance it was tested against said apart, before
    its own why: '+0.0266 ms (+55%), allowed +10% = +0.00482 ms: beyond the allowance, p < 1e-4'
    (``line``: the allowance as a difference better - worse; ``baseline``: the beaten method's mean)."""
    raw, relative = difference.value, difference.value / abs(baseline)
    said = f"{raw:+.3g}{unit} ({relative:+.0%}), allowed {line / abs(baseline):+.0%} = {line:+.3g}{unit}"
    why = verdict.why.replace("the other way round", "beyond the allowance", 1)  # the line is the allowance, not 0
    return replace(verdict, why=f"{said}: {why}" if why else said)


def _order_verdict(tested: OrderTest, paper: Effect | None, unit: float, binary: bool) -> Verdict:
    p_for, p_against = finite(tested.p_for), finite(tested.p_against)
    if p_for is None and p_against is None:
        return Verdict(Outcome.NOT_TESTABLE, "every run gives the same difference: no test")
    sized = tested.size is not None
    if p_against is not None and p_against < INFERENCE.alpha:
        if sized and p_for is not None and p_for < INFERENCE.alpha:
            why = f"the sign agrees, the size does not: the paper's {paper} is absent, {said_p(p_against)}"
        elif sized:
            why = f"the paper's {paper} is absent here, {said_p(p_against)}"
        else:
            why = f"the other way round, {said_p(p_against)}"
        return Verdict(Outcome.NOT_REPRODUCED, why, p_for, p_against)
    if p_for is not None and p_for < INFERENCE.alpha:
        size = f"; consistent with the paper's {paper}" if sized else ""
        return Verdict(Outcome.REPRODUCED, f"{said_p(p_for)}{size}", p_for, p_against)
    smallest = tested.detectable * unit
    detect = f"; {tested.gain.runs} runs detect {smallest:.3g} with 80% power" \
        if math.isfinite(smallest) and smallest > 0 and not binary else ""
    said = said_p(p_for) if p_for is not None else "every run ties"
    size = f"; the paper's {paper} not excluded" if sized else ""
    return Verdict(Outcome.INCONCLUSIVE, f"{said}{detect}{size}", p_for, p_against)
