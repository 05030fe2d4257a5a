"""The papers' claims, tested: each claim one entry of ``conf/claims/<paper>.yaml``.

A claim is a sentence of the paper with the table or page it comes from,
the published cells that belong to it, and one or more *readings*: ways of
testing it on our runs where the paper leaves a choice open (which success
rule, which sigma).  The first reading is the primary one and gives the
claim's verdict; the others say whether the verdict survives another
defensible reading.

A reading names an experiment and a *test*, a small class registered by
name (:class:`ClaimTest`): ``order`` (paired differences between methods on
common random numbers), ``equal_cost`` (the same at equal work: the baseline at the
budget the method spends), ``cells`` (the verdicts of published cells in named
tables), ``threshold`` (a statistic against a bound), ``best`` (a method
first over several sequences, decided by its probability of ranking first) and
``uniformity`` (discrepancies of point sets, no runs).  Each test returns
:class:`Check` values, combined into the reading's :class:`Result`.
"""

import functools
import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pandas as pd
import yaml

from replication.evidence.comparisons import Effect, OrderTest, best_test, order_test
from replication.evidence.inference import mean_test, proportion_test, said_p, sign_test
from replication.evidence.named_conditions import as_mappings, matching
from replication.evidence.original import runs_behind
from replication.evidence.quantities import quantity
from replication.evidence.statistics import Estimate, said_level
from replication.evidence.verdict import OUTCOMES, Outcome, Verdict, decide, too_few
from replication.errors import ConfigError
from replication.paths import CONF_DIR
from replication.qmc import discrepancy_table
from replication.evidence.published import cells as published_cells
from replication.evidence.ranking import rankings, unreliable
from replication.evidence.trends import dominance, log_log_slope
from replication.condition import values_of
from replication.evidence.tables import Table, match, pair, table_specs
from replication.evidence.settings import INFERENCE
from replication.kinds import Registry
from replication.specs import Spec

CLAIMS_DIR = CONF_DIR / "claims"
EQUAL_N = "equal N"  # what a reading at the paper's own settings compares at
WORK = "evaluations_per_step"  # the work counted beside a time (replication.smc.work)


@dataclass(frozen=True, kw_only=True)
class ClaimSpec(Spec):
    """What every reading's test names: the test, and the ``conditions`` it is checked at (each a mapping of
    values, :func:`named`; none: each condition of the runs)."""

    test: str
    conditions: Any = None

    @property
    def naming(self) -> tuple:
        """The options that name conditions, as written (:func:`named` reads them)."""
        return (self.conditions,)

    @property
    def basis(self) -> str:
        """What the methods are compared at: "" where at the paper's own settings (equal N), else the budget
        they are given in common (its label: "likelihood evaluations per step", "time per frame (ms)")."""
        return ""


CLAIM_TESTS: Registry[type["ClaimTest"]] = Registry("claim test")
READING_KEYS = ("name", "experiment", "ours")  # a reading's own keys, beside its test's options


def claim_spec(written: Mapping | ClaimSpec, where: str = "a claim's reading") -> ClaimSpec:
    """A reading's test as its kind declares it (``test:``), checked (:meth:`~replication.specs.Spec.of`)."""
    if isinstance(written, ClaimSpec):
        return written
    if not isinstance(written, Mapping):
        raise ConfigError(f"{where}: a reading is a mapping of options, got {written!r}")
    try:
        made = CLAIM_TESTS[written.get("test")]
    except ConfigError as error:
        raise ConfigError(f"{where}: {error}") from None
    return made.Spec.of({k: v for k, v in written.items() if k not in READING_KEYS}, f"{where} ({made.name})",
                        READING_KEYS)


@dataclass(frozen=True)
class Reading:
    name: str
    experiment: str
    test: ClaimSpec
    ours: str = ""  # what this reading adds to the paper's words (a sequence it did not use, equal cost): never
    # the primary reading's

    @property
    def basis(self) -> str:
        """What the methods are compared at: "" where at the paper's own settings (equal N), else the budget
        they are given in common (its label: "likelihood evaluations per step", "time per frame (ms)")."""
        return self.test.basis

    @property
    def compared_at(self) -> str:
        """The same for a reader: "equal N", or "equal <budget>"."""
        return f"equal {self.basis}" if self.basis else EQUAL_N


@dataclass(frozen=True)
class Quote:
    """The paper's own words for a claim, as its text prints them (``text``, the original language) and
    in English."""

    text: str
    english: str


@dataclass(frozen=True)
class Claim:
    id: str
    paper: str
    text: str  # the claim in plain words, saying no more than its quote
    quote: Quote
    where: str  # section, table or figure (and page) as the paper's text gives them
    cells: dict  # which published cells belong to it: {column: [values]}, every column matching
    readings: tuple[Reading, ...]
    note: str = ""
    untestable: str = ""  # why no reading tests it here (a private video with no stand-in, a lost table)

    def owns(self, cell: pd.Series) -> bool:
        """Whether a published cell (a row of ``published_values.csv``) belongs to this claim."""
        return cell["paper"] == self.paper and bool(self.cells) and all(
            str(cell[column]) in [str(v) for v in _listed(values)] for column, values in self.cells.items())


@dataclass(frozen=True)
class Paper:
    key: str
    title: str
    authors: str
    venue: str
    claims: tuple[Claim, ...]
    path: Path | None = None  # its claims file


@dataclass(frozen=True)
class Check:
    """One comparison inside a reading: what was compared, the number that decided it, its verdict (with the
    p-values it rests on: :class:`Result` applies Holm's correction across the reading's checks)."""

    what: str
    verdict: Verdict
    estimate: Estimate | None = None
    unit: str = ""
    reference: float | None = None  # where the claim's line is: the paper's value, a bound, zero difference
    per_run: dict[int, float] = field(default_factory=dict)  # the statistic per repetition (for the multiverse)
    detail: str = ""  # what it was measured at (a budget, the work spent), shown beside ``what``, not its identity
    paper: float | None = None  # the paper's own value of the number, where it quotes one (a sized order's gap
    # better - worse in the units shown, a cell's published value, a threshold's bound): ours / paper's is the
    # scorecard's common scale (1: as the paper says, 0: no effect)
    timed: bool = False  # the number rests on times measured as the runs ran (machine- and load-dependent)

    @property
    def shown(self) -> str:
        return f"{self.what} ({self.detail})" if self.detail else self.what

    @property
    def number(self) -> str:
        """The estimate with its interval and the interval's level: '0.0266 [0.0243, 0.029] ms (90% CI)'."""
        e = self.estimate
        if e is None:
            return ""
        return f"{e}{self.unit}" + (f" ({said_level(e.level)})" if e.defined else "")

    @property
    def p_values(self) -> tuple[float, float]:
        """(p_for, p_against); a check decided without a test (a deterministic comparison, a stored cell
        verdict of old) counts as certain either way, an untestable one as neither."""
        v = self.verdict
        if v.p_for is not None or v.p_against is not None:
            return (math.nan if v.p_for is None else v.p_for, math.nan if v.p_against is None else v.p_against)
        return {Outcome.REPRODUCED: (0.0, 1.0), Outcome.NOT_REPRODUCED: (1.0, 0.0),
                Outcome.INCONCLUSIVE: (1.0, 1.0), Outcome.NOT_TESTABLE: (math.nan, math.nan)}[v.outcome]


@dataclass(frozen=True)
class Result:
    """A reading's verdict, the check that decided it, and every check."""

    verdict: Verdict
    checks: tuple[Check, ...] = field(default_factory=tuple)
    deciding: Check | None = None

    @classmethod
    def of(cls, checks: list[Check]) -> "Result":
        """The reading's verdict by :func:`~replication.evidence.verdict.decide`: not reproduced where some
        check's evidence against the claim survives Holm across the testable checks, reproduced where every
        testable check holds at 5 % (the why names those that are not testable), else inconclusive; not
        testable where no check is (with the first check's reason).  A check's own verdict is re-stated where
        Holm changes it."""
        if not checks:
            return cls(Verdict(Outcome.NOT_TESTABLE, "no runs to test it on"))
        p_for, p_against = np.array([c.p_values for c in checks]).T
        codes, reading, adjusted = decide(p_for, p_against)
        checks = [_after_holm(c, OUTCOMES[code], p, len(checks)) for c, code, p in zip(checks, codes, adjusted)]
        outcome = OUTCOMES[int(reading)]
        if outcome is Outcome.NOT_TESTABLE:
            return cls(Verdict(Outcome.NOT_TESTABLE, checks[0].verdict.why), tuple(checks), checks[0])
        testable = [i for i, c in enumerate(checks) if c.verdict.outcome is not Outcome.NOT_TESTABLE]
        evidence = np.nan_to_num(p_against, nan=1.0)  # breaks ties: Holm's running maximum, p_for rounded to 1
        if outcome is Outcome.NOT_REPRODUCED:
            i = min((i for i in testable if checks[i].verdict.outcome is outcome),
                    key=lambda i: (adjusted[i], evidence[i]))
        else:  # the weakest check: the largest p-value for the claim, then the most evidence against it
            i = max(testable, key=lambda i: (np.nan_to_num(p_for[i], nan=1.0), -evidence[i]))
        deciding = checks[i]
        untestable = [c for c in checks if c.verdict.outcome is Outcome.NOT_TESTABLE]  # the rule passes over them
        held = sum(c.verdict.outcome is Outcome.REPRODUCED for c in checks)
        tally = f"{held} of {len(testable)} {'testable ' if untestable else ''}checks hold"
        if untestable:
            tally += f"; {len(untestable)} not testable: " + ", ".join(
                f"{c.shown} ({c.verdict.why})" if c.verdict.why else c.shown for c in untestable)
        said = "; ".join(filter(None, [deciding.number, deciding.verdict.why]))
        why = f"{tally}; {deciding.shown}" + (f": {said}" if said else "")
        against = adjusted[i] if outcome is Outcome.NOT_REPRODUCED else p_against[i]  # what decided it
        return cls(Verdict(outcome, why, _finite(p_for[i]), _finite(against)), tuple(checks), deciding)


def _after_holm(check: Check, outcome: Outcome, adjusted: float, family: int) -> Check:
    """The check with the outcome the reading's family gives it (its own test's, unless Holm undoes it)."""
    if outcome is check.verdict.outcome or check.verdict.outcome is Outcome.NOT_TESTABLE:
        return check
    own = check.verdict
    why = f"{own.why}; not significant after Holm across {family} checks ({said_p(adjusted)})" \
        if own.outcome is Outcome.NOT_REPRODUCED else own.why
    return replace(check, verdict=Verdict(outcome, why, own.p_for, own.p_against))


class ClaimTest:
    """How a reading tests its claim; subclasses register by ``name``, declare their options (``Spec``) and
    turn records into checks."""

    name: ClassVar[str]
    Spec: ClassVar[type[ClaimSpec]] = ClaimSpec
    needs_runs: ClassVar[bool] = True  # False for a test of something computed, not run (point sets)

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        CLAIM_TESTS.register(cls.name, cls)

    def __init__(self, spec: ClaimSpec, experiment: dict, published: pd.DataFrame | None = None):
        self.spec, self.experiment, self.published = spec, experiment, published

    @classmethod
    def of(cls, spec: Mapping | ClaimSpec, experiment: dict, published: pd.DataFrame | None = None) -> "ClaimTest":
        """The test a reading names, on its typed spec (a mapping is checked first: :func:`claim_spec`)."""
        spec = claim_spec(spec)
        return CLAIM_TESTS[spec.test](spec, experiment, published)

    def checks(self, records: pd.DataFrame, tables: dict[str, Table]) -> list[Check]:
        raise NotImplementedError

    @property
    def tables(self) -> list[str]:
        """The names of the experiment's tables the test judges (none: it judges the records)."""
        return []

    def conditions(self, records: pd.DataFrame) -> list[str]:
        """The labels of the conditions of ``records`` that the reading names (:func:`named`), each once, in the
        order named; every condition of ``records`` where it names none."""
        wanted = named(self.spec)
        if not wanted:
            return list(dict.fromkeys(records["condition"]))
        return list(dict.fromkeys(label for w in wanted for label in records.loc[matching(records, w), "condition"]))


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
    class Spec(ClaimSpec):
        metric: str
        order: list
        scale: float = 1.0
        unit: str = ""
        tolerance: float = 0.0
        size: dict[str, Any] | None = None

    def checks(self, records, tables):
        metric, scale = self.spec.metric, self.spec.scale
        kind = quantity(metric)
        unit = self.spec.unit
        groups = [_listed(g) for g in self.spec.order]
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
                    paper = self.effect(a, b, records[records["condition"] == condition].iloc[0], len(paired))
                    verdict, difference = _order_check(better, worse, kind, scale, allowed, paper)
                    # the line the difference better - worse is tested against: worse by at most the allowance
                    line = allowed * scale * (1 if kind.lower_is_better else -1)
                    if allowed and verdict.outcome is not Outcome.NOT_TESTABLE:
                        verdict = _allowing(verdict, difference, line, paired["baseline"].mean() * scale, unit)
                    per_run = dict(zip(paired["repetition"].astype(int), (better - worse) * scale))
                    work = _work(records, (a, b), condition) if kind.machine_dependent else ""  # beside a time
                    found.append(Check(what, verdict, difference, unit, line, per_run, work,
                                       _shown_gap(paper), kind.machine_dependent))
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
        for name in _listed(size["table"]):  # the first of the named tables that holds both numbers here
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
    class Spec(ClaimSpec):
        metric: str
        cost: str
        method: str | list[str]
        baseline: str | list[str]
        scale: float = 1.0
        unit: str = ""

        @property
        def basis(self) -> str:
            return quantity(self.cost).label or self.cost

    def checks(self, records, tables):
        metric, cost = self.spec.metric, self.spec.cost
        pairs = itertools.product(_listed(self.spec.method), _listed(self.spec.baseline))
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
            verdict, difference = _order_check(better, worse, quantity(metric), scale, 0.0, None)
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
                 paper: Effect | None) -> tuple[Verdict, Estimate]:
    """One pair's verdict (before the reading's Holm) and the paired difference better - worse shown with
    it, in the claim's units (``scale``): the raw difference, the margin ``allowed`` in the claim's favour
    (in the runs' units) tested but not shown in it."""
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
        return few, difference
    if tested.tied:
        return Verdict(Outcome.NOT_TESTABLE, _tied(float(better[0]), runs, kind, scale)), difference
    return _order_verdict(tested, paper, unit, binary), difference


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
    p_for, p_against = _finite(tested.p_for), _finite(tested.p_against)
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


class Cells(ClaimTest):
    """The published cells this claim owns, as judged in the named tables of ours (``tables:``)."""

    name = "cells"

    @dataclass(frozen=True, kw_only=True)
    class Spec(ClaimSpec):
        tables: str | list[str]

    @property
    def tables(self):
        return _listed(self.spec.tables)

    def checks(self, records, tables):
        found = []
        for name in self.tables:
            table = tables.get(name)
            for cell in [] if table is None else table.cells:
                what = f"{cell.method} {cell.experiment} {cell.condition}".strip()
                if cell.rating:  # a rating: the proportion of runs behind it is the number
                    what = f"{what} (ours: {cell.rating})"
                found.append(Check(what, cell.verdict or Verdict(Outcome.NOT_TESTABLE), cell.estimate,
                                   reference=cell.paper_number, paper=cell.paper_number))
        return found


class Threshold(ClaimTest):
    """``method`` at ``condition`` reaches a bound, ``at_least`` or ``at_most``: the exact sign test of its
    median (``statistic: median``), the exact binomial test of a yes/no rate, else the t-test of its mean,
    one-sided each way.  A check at each of the method's conditions that ``condition`` picks (:func:`named`;
    none: each of them), named in the check where it picks several."""

    name = "threshold"

    @dataclass(frozen=True, kw_only=True)
    class Spec(ClaimSpec):
        method: str
        metric: str
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
        verdict = too_few(len(values)) or _threshold_verdict(_finite(p_for), _finite(p_against))
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


def _threshold_verdict(p_for: float | None, p_against: float | None, against: str = "the other side of the bound",
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


class Best(ClaimTest):
    """``method`` ranks first in mean ``metric`` over the sequences (the condition variable ``over``,
    default ``scene``; ``group``: one value of the ranking's ``by`` variable): one check per competitor, the
    paired t-test over the sequences of the per-sequence difference of their means
    (:func:`~replication.evidence.comparisons.best_test`).  Reproduced where it beats every competitor at 5 %;
    not reproduced where some competitor is better, after Holm across them.  P(best) and the rank interval of
    the two-level bootstrap (:mod:`replication.evidence.ranking`) are shown beside it and decide nothing.  A
    ranking that is not reliable (too few runs or sequences, sequences cut short) decides nothing."""

    name = "best"

    @dataclass(frozen=True, kw_only=True)
    class Spec(ClaimSpec):
        """A method's ranking (:func:`_ranking`): among ``among`` (every method), over the ``sequences``
        (values of ``over``; every one), in the ranking of ``group`` (a value of ``by``)."""

        method: str
        metric: str
        among: list[str] | None = None
        sequences: list[str] | None = None
        over: str = "scene"
        by: str | None = None
        group: str = ""

    def checks(self, records, tables):
        metric, method = self.spec.metric, self.spec.method
        found = _ranking(records, self.spec)
        if found is None:
            return []
        i = found.index(method)
        tested = best_test(found.per_sequence_means, i, found.lower_is_better)
        caveat = unreliable(found, self.experiment)
        rank = found.rank(i)
        description = f"P(best) = {found.p_best[i]:.2f}, rank [{rank.low:.0f}, {rank.high:.0f}] (description only)"
        checks = []
        others = [m for m in found.methods if m != method]
        sign = -1.0 if found.lower_is_better else 1.0
        for j, other in enumerate(others):
            what = f"{method} - {other}, mean {metric} over {len(found.sequences)} sequences x {found.runs} run(s)"
            difference = Estimate(sign * float(tested.gain.value[j]),
                                  *sorted([sign * float(tested.gain.low[j]), sign * float(tested.gain.high[j])]),
                                  len(found.sequences), "sequence-level paired t", 1 - 2 * INFERENCE.alpha)
            if caveat:
                verdict = Verdict(Outcome.NOT_TESTABLE, f"{caveat}; {description}")
            else:
                verdict = _threshold_verdict(_finite(tested.p_for[j]), _finite(tested.p_against[j]),
                                             f"{other} is better", f"; {description}")
            checks.append(Check(what, verdict, difference, reference=0.0))
        return checks


def _ranking(records: pd.DataFrame, spec: "Best.Spec"):
    """The ranking a ``best`` or ``rank`` claim is about (None where its method is not ranked): the runs of its
    ``among`` methods (with ``method``) over its ``sequences`` (values of the variable ``over``), every one where
    unset, in the ranking of its ``group``."""
    keep = pd.Series(True, index=records.index)
    if spec.among:
        keep &= records["method"].isin([spec.method, *spec.among])
    if spec.sequences:
        keep &= values_of(records, spec.over).isin(spec.sequences)
    found = rankings(records[keep], spec.metric, spec.over, spec.by).get(spec.group)
    return found if found is not None and spec.method in found.methods else None


class Rank(ClaimTest):
    """``method`` ranks among the first ``top`` in mean ``metric`` over the sequences (``among``, ``sequences``,
    ``over`` as for ``best``): its 95 % rank set (:func:`~replication.evidence.ranking.rank_set`: the paired
    t-tests over the sequences, Holm across them) within ranks 1 to ``top``: reproduced; wholly below ``top``:
    not reproduced; else inconclusive.  A ranking that is not reliable decides nothing."""

    name = "rank"

    @dataclass(frozen=True, kw_only=True)
    class Spec(Best.Spec):
        top: int

    def checks(self, records, tables):
        method = self.spec.method
        found = _ranking(records, self.spec)
        if found is None:
            return []
        rank, top = found.rank(found.index(method)), self.spec.top
        what = f"{method}'s rank in mean {self.spec.metric} among {len(found.methods)} over {len(found.sequences)} sequences, at most {top}"
        caveat = unreliable(found, self.experiment)
        if caveat:
            verdict = Verdict(Outcome.NOT_TESTABLE, caveat)
        elif rank.high <= top:
            verdict = Verdict(Outcome.REPRODUCED, f"rank set [{rank.low:.0f}, {rank.high:.0f}]")
        elif rank.low > top:
            verdict = Verdict(Outcome.NOT_REPRODUCED, f"rank set [{rank.low:.0f}, {rank.high:.0f}]")
        else:
            verdict = Verdict(Outcome.INCONCLUSIVE, f"rank set [{rank.low:.0f}, {rank.high:.0f}] spans rank {top}")
        return [Check(what, verdict, rank, reference=float(top))]


class Growth(ClaimTest):
    """``method``'s ``metric`` grows with the condition variable ``x`` (its values read as numbers) no faster
    than x^``at_most``: the log-log slope over every run (:func:`~replication.evidence.trends.log_log_slope`),
    reproduced where its upper bound lies below ``at_most``, not reproduced where its lower bound lies above."""

    name = "growth"

    @dataclass(frozen=True, kw_only=True)
    class Spec(ClaimSpec):
        method: str
        metric: str
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
        verdict = _threshold_verdict(_finite(slope.p_below), _finite(slope.p_above), f"faster than {spec.x}^{spec.at_most:g}")
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
                verdict = _threshold_verdict(_finite(tested.p_for), _finite(tested.p_against),
                                             f"{other} is better on both")
                found.append(Check(f"{chosen_label} against {other} (the other minus the chosen: {gains})", verdict,
                                   timed=any(quantity(m).machine_dependent for m in metrics)))
        return found


class Uniformity(ClaimTest):
    """A point set is more uniform than another: lower discrepancy (``method``, e.g. CD) of ``n`` points in
    each of ``dims`` dimensions.  Deterministic point sets: no runs, no interval."""

    name = "uniformity"
    needs_runs = False

    @dataclass(frozen=True, kw_only=True)
    class Spec(ClaimSpec):
        set: str
        than: str
        dims: int | list[int]
        n: int = 400
        method: str = "CD"

    def checks(self, records, tables):
        spec = self.spec
        table = discrepancy_table(n=spec.n, dims=tuple(_listed(spec.dims)), method=spec.method)
        found = []
        for _, row in table.iterrows():
            ours, other = row[spec.set], row[spec.than]
            outcome = Outcome.REPRODUCED if ours < other else Outcome.NOT_REPRODUCED
            found.append(Check(f"{spec.set} vs {spec.than}, s = {int(row['s'])}",
                               Verdict(outcome, f"{ours:.2e} vs {other:.2e}")))
        return found


# -- claims as data ------------------------------------------------------------------------------------


@functools.cache
def load_papers(directory: Path = CLAIMS_DIR) -> tuple[Paper, ...]:
    """Every paper's claims, in the order the papers are numbered (``order:`` in each file); read once
    per process (every experiment's report asks for them)."""
    papers = [_paper(path) for path in sorted(Path(directory).glob("*.yaml"))]
    return tuple(paper for _, paper in sorted(papers, key=lambda item: item[0]))


def load_own_papers(directory: Path) -> tuple[Paper, ...]:
    """A user's claims files (the ``claims_dir`` setting) in the papers' format, judged on the user's own
    reports only; a folder without one, a file lacking a key or a reading naming an unknown test or option
    is one :class:`~replication.errors.ConfigError` line naming the file."""
    paths = sorted(Path(directory).glob("*.yaml"))
    if not paths:
        raise ConfigError(f"claims_dir={directory}: no claims file (*.yaml) there")
    papers = []
    for path in paths:
        try:
            order, paper = _paper(path)
        except (KeyError, TypeError, AttributeError, yaml.YAMLError) as error:
            what = f"lacks the key {error}" if isinstance(error, KeyError) else f"is not in the claims format ({error})"
            raise ConfigError(f"{path} {what}; see conf/claims/*.yaml") from None
        papers.append((order, paper))
    return tuple(paper for _, paper in sorted(papers, key=lambda item: item[0]))


def _paper(path: Path) -> tuple[int, Paper]:
    """One claims file: its paper's ``order`` and the paper with its claims, each reading's test checked
    against the options its kind declares (:func:`claim_spec`), in the file's name."""
    data = yaml.load(path.read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    claims = tuple(
        Claim(id=c["id"], paper=data["paper"], text=c["claim"], quote=Quote(**c.get("quote", {"text": "", "english": ""})),
              where=c.get("where", ""), cells=c.get("cells") or {},
              readings=tuple(_reading(r, f"{path}: claim {c['id']}, reading {r['name']}")
                             for r in c.get("readings") or ()),
              note=c.get("note", ""), untestable=c.get("untestable", ""))
        for c in data["claims"]
    )
    for claim in claims:  # a condition written as a label is refused here, in its file's name
        for reading in claim.readings:
            named(reading.test, f"{path}: claim {claim.id}, reading {reading.name}")
    return data["order"], Paper(data["paper"], data["title"], data["authors"], data["venue"], claims, path)


def _reading(written: dict, where: str) -> Reading:
    """One reading of a claims file: its name, experiment and test (:func:`claim_spec`)."""
    return Reading(written["name"], written["experiment"], claim_spec(written, where), written.get("ours", ""))


def named(spec: ClaimSpec, where: str = "a claim's reading") -> list[dict]:
    """The conditions a reading names (``conditions:``, a threshold's ``condition:``, a pareto's ``chosen:``),
    each a mapping of variables to values that picks every condition taking them
    (:mod:`~replication.evidence.named_conditions`): each condition picked is a check of its own, as each
    condition is where the reading names none."""
    return [condition for value in spec.naming for condition in as_mappings(value, where)]


def evaluate(name: str, experiment: dict, records: pd.DataFrame, tables: dict[str, Table],
             published: pd.DataFrame | None = None,
             papers: tuple[Paper, ...] | None = None) -> dict[str, dict[str, "Result"]]:
    """The results of every reading that names experiment ``name``: {claim id: {reading name: result}}
    (``published``: the paper's numbers, whose sizes the ``order`` tests compare with ours; ``papers``:
    whose claims, the five papers' unless a user's own are given)."""
    results = {}
    for paper in load_papers() if papers is None else papers:
        for claim in paper.claims:
            for reading in claim.readings:
                if reading.experiment != name:
                    continue
                test = ClaimTest.of(reading.test, experiment, published)
                checks = test.checks(records, tables) if len(records) or not test.needs_runs else []
                results.setdefault(claim.id, {})[reading.name] = Result.of(checks)
    return results


def _listed(value) -> list:
    return [] if value is None else list(value) if isinstance(value, (list, tuple)) else [value]


def _finite(value) -> float | None:
    value = float(value)
    return value if math.isfinite(value) else None
