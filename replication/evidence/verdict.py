"""Verdicts as values: whether a published number or claim holds, why, and the p-values that decided it.

A verdict rests on two one-sided tests at :data:`~replication.evidence.inference.ALPHA`:
``p_for``, the evidence that the paper's statement holds (a claimed direction,
or equivalence with a published number), and ``p_against``, the evidence that
it does not (the other direction, or the paper's own size absent, or a
published number outside our interval).  :func:`decide` turns the p-values of
a reading's checks into the checks' and the reading's outcomes: the one rule,
used by the claims and simulated by the calibration.
"""

import math
from dataclasses import dataclass
from enum import Enum

import numpy as np
from scipy import stats

from replication.evidence.inference import clopper_pearson, holm, mean_test, said_p, sign_test
from replication.evidence.quantities import Quantity
from replication.evidence.settings import INFERENCE

BAYES_FLOOR = "bayes_floor"  # the tag of a published RMSE below what any filter achieves on average

class Outcome(Enum):
    REPRODUCED = "reproduced"
    NOT_REPRODUCED = "not reproduced"
    INCONCLUSIVE = "inconclusive"
    NOT_TESTABLE = "not testable"

    @property
    def css(self) -> str:
        return self.name.lower().replace("_", "-")


OUTCOMES = tuple(Outcome)  # the codes decide() returns index this


@dataclass(frozen=True)
class Verdict:
    outcome: Outcome
    why: str = ""
    p_for: float | None = None  # one-sided p-value that the paper's statement holds
    p_against: float | None = None  # p-value of the evidence against it (before Holm)
    tag: str = ""  # what kind of verdict, for code to count: BAYES_FLOOR (never read back from the why)

    def __str__(self) -> str:
        return f"{self.outcome.value} ({self.why})" if self.why else self.outcome.value


def decide(p_for, p_against) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rule: per check (last axis) and for the reading as a whole, from each check's one-sided p-values
    (NaN for a check that is not testable).

    Returns (check codes, reading codes, Holm-adjusted p_against), codes indexing :data:`OUTCOMES`.  A check
    is not reproduced where its p_against survives Holm across the reading's testable checks, reproduced
    where its p_for < INFERENCE.alpha (and nothing against it survives), else inconclusive.  The reading: not
    reproduced where any check is; reproduced where every testable check is (intersection-union); not
    testable where no check is; else inconclusive.
    """
    p_for, p_against = np.asarray(p_for, dtype=float), np.asarray(p_against, dtype=float)
    testable = np.isfinite(p_for) | np.isfinite(p_against)
    adjusted = holm(np.where(testable, np.nan_to_num(p_against, nan=1.0), np.nan))
    against = testable & (adjusted < INFERENCE.alpha)
    held = testable & ~against & (np.nan_to_num(p_for, nan=1.0) < INFERENCE.alpha)
    codes = np.select([~testable, against, held], [3, 1, 0], 2)
    any_testable = testable.any(axis=-1)
    reading = np.select([~any_testable, against.any(axis=-1), (held | ~testable).all(axis=-1)], [3, 1, 0], 2)
    return codes, reading, adjusted


def too_few(runs: int) -> Verdict | None:
    """The verdict for fewer than :data:`INFERENCE.min_runs` runs, else None."""
    return Verdict(Outcome.NOT_TESTABLE, f"too few runs ({runs})") if runs < INFERENCE.min_runs else None


def judge_value(paper: float, values, quantity: Quantity, statistic: str = "mean", paper_runs: int | None = None,
                floor: np.ndarray | None = None, tolerance: float | None = None) -> Verdict | None:
    """A published number against our per-run ``values`` of the same quantity; None when the paper has no
    number.  ``floor``: the Bayes floor's per-run values on the same data (an RMSE below it is not
    reproduced); ``tolerance``: the relative margin of equivalence (None: the inference setting's)."""
    if paper is None or not math.isfinite(paper):
        return None
    tolerance = INFERENCE.tolerance if tolerance is None else tolerance
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if quantity.machine_dependent:
        typical = float(np.median(values)) if len(values) else math.nan
        return Verdict(Outcome.NOT_TESTABLE, f"machine-dependent; ours/theirs = {typical / paper:.2f}"
                       if paper else "machine-dependent")
    few = too_few(len(values))
    if few:
        return few
    if floor is not None and len(floor) >= INFERENCE.min_runs:
        below = mean_test(floor, paper).p_above  # H1: the floor lies above the paper's value
        if np.isfinite(below) and below < INFERENCE.alpha:
            return Verdict(Outcome.NOT_REPRODUCED, f"below the Bayes floor {np.mean(floor):.3g} ({said_p(below)})",
                           None, float(below), BAYES_FLOOR)
    if quantity.proportion:
        return _judge_rate(paper, values, quantity, paper_runs, tolerance * abs(paper))
    p_for, p_against = cell_test(paper, values, tolerance, paper_runs, statistic)
    if not (np.isfinite(p_against) and np.isfinite(p_for)):
        return Verdict(Outcome.NOT_TESTABLE, f"every run gives {values[0]:.4g}: no interval")
    return _cell(paper, float(np.mean(values)), float(p_for), float(p_against), tolerance)


def cell_test(paper: float, values, tolerance: float | None = None, paper_runs: int | None = None,
              statistic: str = "mean") -> tuple[np.ndarray, np.ndarray]:
    """(p_for, p_against) of a published number against per-run ``values`` (last axis: runs), the band of
    ``tolerance`` x |paper| around it counting as the same number: p_for, that ours lies inside the band
    (two one-sided tests, equivalence); p_against, that it lies outside (the smaller one-sided p-value at
    the band's edges, doubled: a two-sided test at 5 %, whose null holds whenever the paper's value is
    ours).  The t-test's standard error is widened by sqrt(1 + runs / ``paper_runs``) for the published
    mean's own noise."""
    values = np.asarray(values, dtype=float)
    margin = (INFERENCE.tolerance if tolerance is None else tolerance) * abs(paper)
    test = sign_test if statistic == "median" else mean_test
    if statistic != "median" and paper_runs:  # spread about the mean: the t-test's standard error grows alike
        centre = values.mean(axis=-1, keepdims=True)
        values = centre + math.sqrt(1 + values.shape[-1] / paper_runs) * (values - centre)
    low, high = test(values, paper - margin), test(values, paper + margin)
    p_for = np.maximum(low.p_above, high.p_below)
    if test is mean_test:
        p_for = np.minimum(1.0, p_for * (INFERENCE.alpha / INFERENCE.equivalence_alpha))
    return p_for, np.minimum(1.0, 2 * np.minimum(low.p_below, high.p_above))


def _judge_rate(paper: float, values: np.ndarray, quantity: Quantity, paper_runs: int | None,
                margin: float) -> Verdict:
    """A published rate against ours: Fisher's exact test where the paper's run count is known (else the
    exact binomial test at the paper's rate), equivalence by our Clopper-Pearson 90 % interval."""
    runs, successes = len(values), int(round(values.sum() / quantity.high))
    rate, theirs = paper / quantity.high, margin / quantity.high
    if paper_runs:
        k = int(round(rate * paper_runs))
        p_against = float(stats.fisher_exact([[successes, runs - successes], [k, paper_runs - k]]).pvalue)
    else:
        p_against = float(stats.binomtest(successes, runs, min(max(rate, 0.0), 1.0)).pvalue)
    low, high = clopper_pearson(successes, runs, 1 - 2 * INFERENCE.alpha)
    p_for = 0.0 if rate - theirs <= low and high <= rate + theirs else 1.0  # equivalence: inside the margin
    return _cell(paper, successes / runs * quantity.high, p_for, p_against, margin / abs(paper) if paper else 0.0)


def _cell(paper: float, ours: float, p_for: float, p_against: float, tolerance: float) -> Verdict:
    """A cell's verdict by :func:`decide`, said with our mean's gap and the band: '-8%, outside 4.18 +- 0.418'."""
    difference = f"{(ours - paper) / abs(paper):+.0%}" if paper else f"{ours - paper:+.3g}"
    band = f"{paper:.4g} +- {tolerance * abs(paper):.3g}"
    outcome = OUTCOMES[int(decide([p_for], [p_against])[1])]
    if outcome is Outcome.NOT_REPRODUCED:
        return Verdict(outcome, f"{difference}, outside {band}, {said_p(p_against)}", p_for, p_against)
    if outcome is Outcome.REPRODUCED:
        return Verdict(outcome, f"within {band}, TOST {said_p(p_for)} (on the 5 % scale)", p_for, p_against)
    return Verdict(outcome, f"{difference}: neither shown within {band} nor outside it", p_for, p_against)


def judge_band(paper: str, successes: int, runs: int, bands: dict[str, tuple[float, float]]) -> Verdict:
    """A published category (a stability rating, success / failure) against our count of runs: each
    category is a band of the rate; reproduced when only the paper's band meets the 95 % Clopper-Pearson
    interval, not reproduced when the paper's band does not."""
    few = too_few(runs)
    if few:
        return few
    low, high = (float(v) for v in clopper_pearson(successes, runs, 1 - INFERENCE.alpha))
    rate = successes / runs
    met = [name for name, (lo, hi) in bands.items() if low <= hi and high >= lo]
    ours = next((name for name, (lo, hi) in bands.items() if lo <= rate <= hi), "?")
    p_against = _band_p(successes, runs, bands[paper]) if paper in bands else math.nan
    p_for = max((_band_p(successes, runs, band) for name, band in bands.items() if name != paper), default=0.0)
    if paper not in met:
        return Verdict(Outcome.NOT_REPRODUCED, f"ours: {ours}", p_for, p_against)
    if met == [paper]:
        return Verdict(Outcome.REPRODUCED, "", p_for, p_against)
    return Verdict(Outcome.INCONCLUSIVE, f"the interval admits {' and '.join(met)}", p_for, p_against)


def stability_bands(per: int = 10) -> dict[str, tuple[float, float]]:
    """bis_pf's ratings as bands of the failure probability: good = no failure in 10 runs, medium = 2 or
    more, poor = 5 or more; one failure in 10 (unrated by the paper) is split between good and medium."""
    return {"good": (0.0, 1.5 / per), "medium": (1.5 / per, 4.5 / per), "poor": (4.5 / per, 1.0)}


def _band_p(successes: int, runs: int, band: tuple[float, float]) -> float:
    """The exact two-sided p-value of the rate lying in ``band``, from its nearest edge (1 inside it)."""
    low, high = band
    if successes < low * runs:
        return float(min(1.0, 2 * stats.binom.cdf(successes, runs, low)))
    if successes > high * runs:
        return float(min(1.0, 2 * stats.binom.sf(successes - 1, runs, high)))
    return 1.0

