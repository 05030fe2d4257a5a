"""Verdicts as values: whether a published number or claim holds, and why.

A published cell is judged against our estimate of the same quantity; a claim
against the estimates its readings name (``replication.report.claims``).
Both give a :class:`Verdict`: one of four outcomes and one line of why.
"""

import math
from dataclasses import dataclass
from enum import Enum

from replication.report.quantities import Quantity
from replication.report.statistics import Estimate, rate_test

MIN_RUNS = 5  # no verdict from fewer runs

RULES = (
    "reproduced: the published value lies inside the 95% interval a published estimate should fall in if it "
    "estimates what ours does (our interval, widened by sqrt(1 + our runs / their runs) for the paper's own "
    "Monte Carlo noise where its run count is known; a rate with a known run count: Fisher's exact test, p >= 0.05). "
    "not reproduced: it lies outside (the signed difference is ours minus theirs, relative to theirs), or it is "
    "below the Bayes floor, the point-mass filter's RMSE, which no filter beats on average under the model. "
    "inconclusive: the interval admits the paper's answer and another (a rating, a mode count, an ordering whose "
    "paired interval contains zero). "
    "not testable: a timing (machine-dependent: the ratio ours / theirs is shown), fewer than 5 runs, or no data. "
    "Intervals: Wilson for yes/no outcomes per run, BCa bootstrap over runs for means (never outside the metric's "
    "range), order statistics for medians, paired BCa bootstrap for differences between methods on common random "
    "numbers."
)


class Outcome(Enum):
    REPRODUCED = "reproduced"
    NOT_REPRODUCED = "not reproduced"
    INCONCLUSIVE = "inconclusive"
    NOT_TESTABLE = "not testable"

    @property
    def css(self) -> str:
        return self.name.lower().replace("_", "-")


@dataclass(frozen=True)
class Verdict:
    outcome: Outcome
    why: str = ""

    def __str__(self) -> str:
        return f"{self.outcome.value} ({self.why})" if self.why else self.outcome.value

    def as_dict(self) -> dict:
        return {"outcome": self.outcome.value, "why": self.why}

    @classmethod
    def from_dict(cls, data: dict) -> "Verdict":
        return cls(Outcome(data["outcome"]), data.get("why", ""))


def too_few(runs: int) -> Verdict | None:
    """The verdict for fewer than :data:`MIN_RUNS` runs, else None."""
    return Verdict(Outcome.NOT_TESTABLE, f"too few runs ({runs})") if runs < MIN_RUNS else None


def judge_value(paper: float, ours: Estimate, quantity: Quantity, paper_runs: int | None = None,
                floor_low: float | None = None) -> Verdict | None:
    """A published number against our estimate of the same quantity; None when the paper has no number."""
    if paper is None or not math.isfinite(paper):
        return None
    if quantity.machine_dependent:
        ratio = ours.value / paper if paper else math.nan
        return Verdict(Outcome.NOT_TESTABLE, f"machine-dependent; ours/theirs = {ratio:.2f}")
    few = too_few(ours.runs)
    if few:
        return few
    if floor_low is not None and paper < floor_low:
        return Verdict(Outcome.NOT_REPRODUCED, f"below the Bayes floor {floor_low:.3g}")
    difference = f"{(ours.value - paper) / abs(paper):+.0%}" if paper else f"{ours.value - paper:+.3g}"
    if quantity.proportion and paper_runs:
        p = rate_test(round(ours.value / quantity.high * ours.runs), ours.runs, paper / quantity.high, paper_runs)
        outcome = Outcome.REPRODUCED if p >= 0.05 else Outcome.NOT_REPRODUCED
        return Verdict(outcome, f"Fisher's exact test p = {p:.2g}, {difference}")
    interval = comparison(ours, quantity, paper_runs)
    if not interval.defined:
        return Verdict(Outcome.NOT_TESTABLE, "no interval")
    if interval.contains(paper):
        return Verdict(Outcome.REPRODUCED)
    return Verdict(Outcome.NOT_REPRODUCED, difference)


def comparison(ours: Estimate, quantity: Quantity, paper_runs: int | None) -> Estimate:
    """The interval a published estimate over ``paper_runs`` runs should fall in (ours where unknown)."""
    return ours.widened(math.sqrt(1 + ours.runs / paper_runs), quantity) if paper_runs else ours


def judge_band(paper: str, ours: Estimate, bands: dict[str, tuple[float, float]]) -> Verdict:
    """A published category (a stability rating, success / failure) against our proportion's interval:
    each category is a band of the proportion; reproduced when only the paper's band meets the interval."""
    few = too_few(ours.runs)
    if few:
        return few
    met = [name for name, (low, high) in bands.items() if ours.low <= high and ours.high >= low]
    ours_name = next((name for name, (low, high) in bands.items() if low <= ours.value <= high), "?")
    if paper not in met:
        return Verdict(Outcome.NOT_REPRODUCED, f"ours: {ours_name}")
    if met == [paper]:
        return Verdict(Outcome.REPRODUCED)
    return Verdict(Outcome.INCONCLUSIVE, f"the interval admits {' and '.join(met)}")
