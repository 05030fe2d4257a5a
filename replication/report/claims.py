"""The papers' claims, tested: each claim one entry of ``conf/claims/<paper>.yaml``.

A claim is a sentence of the paper with the table or page it comes from,
the published cells that belong to it, and one or more *readings*: ways of
testing it on our runs where the paper leaves a choice open (which success
rule, which sigma).  The first reading is the primary one and gives the
claim's verdict; the others say whether the verdict survives another
defensible reading.

A reading names an experiment and a *test*, a small class registered by
name (:class:`ClaimTest`): ``order`` (paired differences between methods on
common random numbers), ``cells`` (the verdicts of published cells in named
tables), ``threshold`` (a statistic against a bound), ``best`` (a method
first over several sequences, decided by its probability of ranking first) and
``uniformity`` (discrepancies of point sets, no runs).  Each test returns
:class:`Check` values, combined into the reading's :class:`Result`.
"""

import functools
import itertools
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

import numpy as np
import pandas as pd
import yaml

from replication.paths import CONF_DIR
from replication.qmc import discrepancy_table
from replication.report.quantities import quantity
from replication.report.ranking import rankings, unreliable
from replication.report.statistics import Estimate, estimate, paired_difference
from replication.report.tables import Table, pair
from replication.report.verdict import Outcome, Verdict, too_few

CLAIMS_DIR = CONF_DIR / "claims"
# A "best" claim holds when the method ranks first in at least 95% of the bootstrap resamples (the level
# of every interval here) and fails when it does in at most 5% (so also when another method's P(best) is
# at least 0.95); between, the sequences and runs leave it open.
FIRST = 0.95
NOT_FIRST = 0.05


@dataclass(frozen=True)
class Reading:
    name: str
    experiment: str
    test: dict


@dataclass(frozen=True)
class Claim:
    id: str
    paper: str
    text: str
    source: str
    cells: dict  # which published cells belong to it: {column: [values]}, every column matching
    readings: tuple[Reading, ...]
    note: str = ""

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


@dataclass(frozen=True)
class Check:
    """One comparison inside a reading: what was compared, the number that decided it, its verdict."""

    what: str
    verdict: Verdict
    estimate: Estimate | None = None
    unit: str = ""
    reference: float | None = None  # where the claim's line is: the paper's value, a bound, zero difference

    @property
    def number(self) -> str:
        return "" if self.estimate is None else f"{self.estimate}{self.unit}"


@dataclass(frozen=True)
class Result:
    """A reading's verdict, the check that decided it, and every check."""

    verdict: Verdict
    checks: tuple[Check, ...] = field(default_factory=tuple)
    deciding: Check | None = None

    @classmethod
    def of(cls, checks: list[Check]) -> "Result":
        """Every check reproduced: reproduced; any not reproduced: not reproduced; else inconclusive;
        no check testable: not testable (with the first check's reason)."""
        if not checks:
            return cls(Verdict(Outcome.NOT_TESTABLE, "no runs to test it on"))
        testable = [c for c in checks if c.verdict.outcome is not Outcome.NOT_TESTABLE]
        if not testable:
            return cls(Verdict(Outcome.NOT_TESTABLE, checks[0].verdict.why), tuple(checks), checks[0])
        for outcome in (Outcome.NOT_REPRODUCED, Outcome.INCONCLUSIVE):
            deciding = next((c for c in testable if c.verdict.outcome is outcome), None)
            if deciding:
                break
        else:
            outcome, deciding = Outcome.REPRODUCED, testable[0]
        held = sum(c.verdict.outcome is Outcome.REPRODUCED for c in testable)
        said = "; ".join(filter(None, [deciding.number, deciding.verdict.why]))
        why = f"{held} of {len(testable)} checks hold; {deciding.what}" + (f": {said}" if said else "")
        return cls(Verdict(outcome, why), tuple(checks), deciding)

    def as_dict(self) -> dict:
        def check(c: Check) -> dict:
            e = c.estimate
            return {"what": c.what, "verdict": c.verdict.as_dict(), "number": c.number,
                    "value": _number(e.value) if e else None, "low": _number(e.low) if e else None,
                    "high": _number(e.high) if e else None, "runs": e.runs if e else None,
                    "reference": c.reference}

        return {"verdict": self.verdict.as_dict(), "checks": [check(c) for c in self.checks],
                "deciding": check(self.deciding) if self.deciding else None}


class ClaimTest:
    """How a reading tests its claim; subclasses register by ``name`` and turn records into checks."""

    name: ClassVar[str]
    needs_runs: ClassVar[bool] = True  # False for a test of something computed, not run (point sets)
    registry: ClassVar[dict[str, type["ClaimTest"]]] = {}

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        ClaimTest.registry[cls.name] = cls

    def __init__(self, spec: dict, experiment: dict):
        self.spec, self.experiment = spec, experiment

    @classmethod
    def of(cls, spec: dict, experiment: dict) -> "ClaimTest":
        if spec.get("test") not in cls.registry:
            raise ValueError(f"unknown claim test {spec.get('test')!r}; known: {sorted(cls.registry)}")
        return cls.registry[spec["test"]](spec, experiment)

    def checks(self, records: pd.DataFrame, tables: dict[str, Table]) -> list[Check]:
        raise NotImplementedError

    @property
    def tables(self) -> list[str]:
        """The names of the experiment's tables the test judges (none: it judges the records)."""
        return []

    def conditions(self, records: pd.DataFrame) -> list[str]:
        return [str(c) for c in _listed(self.spec.get("conditions"))] or list(dict.fromkeys(records["condition"]))


class Order(ClaimTest):
    """``order: [A, [B, C], D]``: A beats B and C, each of which beats D, on ``metric``, at each condition.

    Each pair is judged by the mean paired difference over runs that filtered
    the same data (BCa bootstrap): reproduced when its interval lies on the
    claimed side of zero, not reproduced when it lies on the other side or at
    zero, inconclusive when it straddles zero.  ``tolerance`` (a fraction of
    the beaten method's mean) turns "better" into "no worse than by more than
    that" (a claim of equal cost, say).
    """

    name = "order"

    def checks(self, records, tables):
        metric, scale = self.spec["metric"], self.spec.get("scale", 1.0)
        lower = quantity(metric).lower_is_better
        unit = self.spec.get("unit", "")
        groups = [_listed(g) for g in self.spec["order"]]
        found = []
        for condition in self.conditions(records):
            for better, worse in zip(groups, groups[1:]):
                for a, b in itertools.product(better, worse):
                    paired = pair(records, metric, b, a, condition)
                    what = f"{a} - {b}" + (f" at {condition}" if condition else "")
                    if paired.empty:
                        continue
                    difference = paired_difference(paired["method"] * scale, paired["baseline"] * scale)
                    allowed = self.spec.get("tolerance", 0.0) * abs(paired["baseline"].mean() * scale)
                    found.append(Check(what, _judge_sign(difference, lower, allowed), difference, unit, 0.0))
        return found


class Cells(ClaimTest):
    """The published cells this claim owns, as judged in the named tables of ours (``tables:``)."""

    name = "cells"

    @property
    def tables(self):
        return _listed(self.spec["tables"])

    def checks(self, records, tables):
        found = []
        for name in self.tables:
            table = tables.get(name)
            for entry in [] if table is None else table.cells:
                estimate = None
                if entry.get("value") is not None:
                    estimate = Estimate(entry["value"], entry["ci_low"] if entry["ci_low"] is not None else math.nan,
                                        entry["ci_high"] if entry["ci_high"] is not None else math.nan,
                                        entry["runs"], entry.get("interval", ""))
                what = f"{entry['method']} {entry['experiment']} {entry['condition']}".strip()
                verdict = Verdict.from_dict(entry["verdict"]) if entry["verdict"] else Verdict(Outcome.NOT_TESTABLE)
                if isinstance(entry["ours"], str):  # a rating: the proportion of runs behind it is the number
                    what = f"{what} (ours: {entry['ours']})"
                found.append(Check(what, verdict, estimate, reference=_number(_float(entry.get("paper")))))
        return found


class Threshold(ClaimTest):
    """``method`` at ``condition`` reaches a bound: ``at_least`` or ``at_most``, on the statistic's interval."""

    name = "threshold"

    def checks(self, records, tables):
        spec = self.spec
        chosen = records[(records["method"] == spec["method"]) & (records["condition"] == spec.get("condition", ""))]
        if chosen.empty:
            return []
        metric = spec["metric"]
        found = estimate(chosen[metric].to_numpy(float), quantity(metric), spec.get("statistic", "mean"))
        bound, above = (spec["at_least"], True) if "at_least" in spec else (spec["at_most"], False)
        what = f"{spec['method']} {metric} {'>=' if above else '<='} {bound:g}"
        verdict = too_few(found.runs)
        if verdict is None:
            low, high = (found.low, found.high) if above else (-found.high, -found.low)
            bound_ = bound if above else -bound
            verdict = (Verdict(Outcome.REPRODUCED) if low >= bound_ else Verdict(Outcome.NOT_REPRODUCED)
                       if high < bound_ else Verdict(Outcome.INCONCLUSIVE, "the interval straddles the bound"))
        return [Check(what, verdict, found, spec.get("unit", ""), float(bound))]


class Best(ClaimTest):
    """``method`` ranks first in mean ``metric`` over the sequences (the condition variable ``over``,
    default ``scene``; ``group``: one value of the ranking's ``by`` variable), decided by its probability
    of ranking first under the two-level bootstrap of :mod:`replication.report.ranking`, not by the
    means: reproduced at ``P(best) >=`` :data:`FIRST`, not reproduced at ``<=`` :data:`NOT_FIRST` (which
    also holds whenever another method's is at least :data:`FIRST`), inconclusive between.  A ranking
    that is not reliable (too few runs or sequences, sequences cut short) decides nothing."""

    name = "best"

    def checks(self, records, tables):
        metric, method = self.spec["metric"], self.spec["method"]
        found = rankings(records, self.spec).get(self.spec.get("group", ""))
        if found is None or method not in found.methods:
            return []
        i, top = found.index(method), int(np.argmax(found.p_best))
        p = float(found.p_best[i])
        what = (f"{method} first in mean {metric} over {len(found.sequences)} sequences x {found.runs} "
                f"run(s): P(best), two-level bootstrap")
        rank = found.rank(i)
        leader = f"; first most often: {found.methods[top]} ({found.p_best[top]:.2f})" if top != i else ""
        caveat = unreliable(found, self.experiment)
        if caveat:
            outcome, against = Outcome.NOT_TESTABLE, ""
        elif p >= FIRST:
            outcome, against = Outcome.REPRODUCED, f" >= {FIRST}"
        elif p <= NOT_FIRST:
            outcome, against = Outcome.NOT_REPRODUCED, f" <= {NOT_FIRST}"
        else:
            outcome, against = Outcome.INCONCLUSIVE, f", between {NOT_FIRST} and {FIRST}"
        said = f"P(best) = {p:.2f}{against}, rank [{rank.low:.0f}, {rank.high:.0f}]{leader}"
        verdict = Verdict(outcome, f"{caveat}; {said}" if caveat else said)
        estimate = Estimate(p, math.nan, math.nan, len(found.sequences) * found.runs, "two-level bootstrap")
        return [Check(what, verdict, estimate, reference=FIRST)]


class Uniformity(ClaimTest):
    """A point set is more uniform than another: lower discrepancy (``method``, e.g. CD) of ``n`` points in
    each of ``dims`` dimensions.  Deterministic point sets: no runs, no interval."""

    name = "uniformity"
    needs_runs = False

    def checks(self, records, tables):
        spec = self.spec
        table = discrepancy_table(n=spec.get("n", 400), dims=tuple(_listed(spec["dims"])),
                                  method=spec.get("method", "CD"))
        found = []
        for _, row in table.iterrows():
            ours, other = row[spec["set"]], row[spec["than"]]
            outcome = Outcome.REPRODUCED if ours < other else Outcome.NOT_REPRODUCED
            found.append(Check(f"{spec['set']} vs {spec['than']}, s = {int(row['s'])}",
                               Verdict(outcome, f"{ours:.2e} vs {other:.2e}")))
        return found


def _judge_sign(difference: Estimate, lower_is_better: bool, allowed: float) -> Verdict:
    """A paired difference (claimed better minus claimed worse) against the claim that it is better."""
    few = too_few(difference.runs)
    if few:
        return few
    low, high = (-difference.high, -difference.low) if lower_is_better else (difference.low, difference.high)
    low, high = low + allowed, high + allowed  # in favour of the claim: positive
    if low > 0:
        return Verdict(Outcome.REPRODUCED)
    if high <= 0:
        return Verdict(Outcome.NOT_REPRODUCED, "the other way round" if high < 0 else "no difference")
    return Verdict(Outcome.INCONCLUSIVE, "the interval contains zero")


# -- claims as data ------------------------------------------------------------------------------------


@functools.cache
def load_papers(directory: Path = CLAIMS_DIR) -> tuple[Paper, ...]:
    """Every paper's claims, in the order the papers are numbered (``order:`` in each file); read once
    per process (every experiment's report asks for them)."""
    papers = []
    for path in sorted(Path(directory).glob("*.yaml")):
        data = yaml.load(path.read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
        claims = tuple(
            Claim(id=c["id"], paper=data["paper"], text=c["claim"], source=c["source"], cells=c.get("cells") or {},
                  readings=tuple(Reading(r["name"], r["experiment"], {k: v for k, v in r.items()
                                                                      if k not in ("name", "experiment")})
                                 for r in c["readings"]),
                  note=c.get("note", ""))
            for c in data["claims"]
        )
        papers.append((data["order"], Paper(data["paper"], data["title"], data["authors"], data["venue"], claims)))
    return tuple(paper for _, paper in sorted(papers, key=lambda item: item[0]))


def evaluate(name: str, experiment: dict, records: pd.DataFrame, tables: dict[str, Table]) -> dict:
    """The results of every reading that names experiment ``name``: {claim id: {reading name: result}}."""
    results = {}
    for paper in load_papers():
        for claim in paper.claims:
            for reading in claim.readings:
                if reading.experiment != name:
                    continue
                test = ClaimTest.of(reading.test, experiment)
                checks = test.checks(records, tables) if len(records) or not test.needs_runs else []
                results.setdefault(claim.id, {})[reading.name] = Result.of(checks).as_dict()
    return results


def _listed(value) -> list:
    return [] if value is None else list(value) if isinstance(value, (list, tuple)) else [value]


def _float(value) -> float:
    """A published value as a number (NaN for a rating or an empty cell)."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def _number(value) -> float | None:
    return float(value) if value is not None and math.isfinite(value) else None
