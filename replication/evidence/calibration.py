"""How often each verdict rule errs: its operating characteristics, simulated through the code that decides.

Each *kind* of test draws many simulated experiments at once, at the run and
check counts the quick and paper scales use, and passes them through the same
functions the claims and tables call (:func:`~replication.evidence.comparisons.order_test`,
:func:`~replication.evidence.comparisons.best_test`, the tests of
:mod:`~replication.evidence.inference`, :func:`~replication.evidence.verdict.cell_test`,
:func:`~replication.evidence.verdict.judge_band`, and the one rule
:func:`~replication.evidence.verdict.decide`).  A row counts how often a verdict comes out:

* ``truth = "null"``: the world in which the verdict the row ``guards`` is wrong
  ("reproduced" guarded by no effect, or one at the edge of equivalence; "not
  reproduced" guarded by the paper's statement being true: no effect for a sign
  claim, the paper's own size for a sized one, the paper's value for a cell).
  ``rate`` is the share of wrong decisive verdicts, to be at most 5 %;
* ``truth = "effect"``: an effect of ``effect`` standard deviations in the
  claim's favour (``guards = "reproduced"``: ``rate`` is the power) or against
  it (``guards = "not reproduced"``).

A paper's size is itself an estimate: its rows (``paper_runs``) draw the
paper's two numbers as means of ``paper_runs`` runs each, from the same noise as
ours but unpaired, its true effect ours in the null and twice ours in the effect
rows (ours at half the paper's size), at the papers' counts and at ours.

Noise, standardised to mean 0 and standard deviation 1: ``normal``, ``t3``
(heavy tails) and ``lognormal`` (skewed, sigma = 0.5: skewness 1.75).  Two
methods compared on common random numbers share a run's draw and add their
own, so under the null they are interchangeable and a run's difference is
symmetric whatever the noise; a single mean against a published number has no
such symmetry, and no test of a mean holds its level under every skew
(Bahadur & Savage 1956): its equivalence test runs at the size-corrected level
:data:`~replication.evidence.verdict.EQUIVALENCE_ALPHA` that these rows set,
and they are simulated at both edges of the band.

Control rows (``control``) run the rules this project used before (a BCa
bootstrap interval at 5 runs; any check against the claim failing it, with no
correction; a method best when it ranked first in 95 % of bootstrap resamples,
not best at 5 %; the paper's size taken as exact, at the size test's level), so
the simulation is seen to catch a bad rule.
"""

import itertools
import math
import zlib
from dataclasses import dataclass
from typing import Callable

import numpy as np
import pandas as pd
from scipy import stats

from replication.evidence.comparisons import Effect, best_test, order_test
from replication.evidence.criteria import CRITERION
from replication.evidence.original import PaperRuns
from replication.evidence.inference import holm, mean_test, sign_test
from replication.evidence.ranking import rank, rank_set
from replication.evidence.robustness import depends
from replication.evidence.trends import dominance, log_log_slope
from replication.evidence.quantities import Quantity
from replication.evidence.verdict import OUTCOMES, Outcome, cell_test, decide, judge_band, judge_value, stability_bands
from replication.evidence.settings import INFERENCE
from replication.evidence.tables.non_inferiority import at_most, no_worse

REPLICATIONS = 10_000  # make calibrate: a Monte Carlo standard error of at most 0.005 on every row
QUICK_REPLICATIONS = 800  # the test suite's version
SEED = 20261125
DISTRIBUTIONS = ("normal", "t3", "lognormal")
LOGNORMAL_SIGMA = 0.5
# The paired run counts the claims' experiments use: 5 (bis_pf, ism_pf quick; hspf's runs per sequence),
# 6 (fusion_pf quick), 10 (bis_pf paper), 20 (gps_qmcpf, hspf_ungm quick; helicopter paper), 30
# (ism_pf_particles paper: ism_pf.accuracy at equal cost), 50 (fusion_pf paper), 100 (gps_qmcpf, hspf_ungm,
# ism_pf paper).  tests/test_calibration.py checks the list is complete.
RUNS = (5, 6, 10, 20, 30, 50, 100)
CHAINS = (6, 9)  # checks in a reading: ism_pf.accuracy (2 pairs x 3 scenes), gps_qmcpf.rmse (3 x 3)
EFFECTS = (0.5, 1.0)
BAR_RULES = ("no worse", "at most")  # issue 61's bar, at bis_pf_pets' 10 runs (5 at the quick scale)
PAPER_RUNS = (10, 20, 100)  # the papers' counts behind a size: bis_pf; fusion_pf's fewest, the helicopter; ism_pf
COLUMNS = ["test", "runs", "checks", "distribution", "truth", "guards", "effect", "paper_runs", "rate", "mc_se",
           "wrong_rate", "power", "holds", "control", "criterion", "replications"]
CALIBRATED_CRITERIA = ("sceptical", "prediction")  # the replication criteria simulated (criteria.py): issue 60
SUCCESS = "replication success"  # what a criterion's row counts
REPRODUCED, NOT_REPRODUCED = OUTCOMES.index(Outcome.REPRODUCED), OUTCOMES.index(Outcome.NOT_REPRODUCED)


def noise(distribution: str, rng: np.random.Generator, shape) -> np.ndarray:
    """Draws with mean 0 and standard deviation 1."""
    if distribution == "normal":
        return rng.standard_normal(shape)
    if distribution == "t3":
        return rng.standard_t(3, shape) / math.sqrt(3.0)
    if distribution == "lognormal":
        mean, sd = _lognormal_moments()
        return (rng.lognormal(0.0, LOGNORMAL_SIGMA, shape) - mean) / sd
    raise ValueError(f"unknown distribution {distribution!r}; known: {DISTRIBUTIONS}")


@dataclass(frozen=True)
class Case:
    """One row to simulate: ``draw(rng, replications)`` returns each replication's verdict code."""

    test: str
    runs: int
    checks: int
    distribution: str
    truth: str
    guards: str
    effect: float
    draw: Callable[[np.random.Generator, int], np.ndarray]
    control: bool = False
    paper_runs: float = math.nan  # the runs behind each of the paper's simulated numbers (a size's rows)
    criterion: bool = False  # a replication criterion's success rate: shown, not a verdict rule held to 5 %


def _pairs(rng, reps: int, runs: int, distribution: str, gains) -> tuple[np.ndarray, np.ndarray]:
    """Per-run values of a claimed-better and a claimed-worse method on common random numbers (higher is
    better), the better one ahead by ``gains`` (per check, in standard deviations of a run's difference)."""
    gains = np.asarray(gains, dtype=float)
    shape = (reps, *gains.shape, runs)
    shared = noise(distribution, rng, shape)
    worse = shared + noise(distribution, rng, shape)
    better = shared + noise(distribution, rng, shape) + (gains * math.sqrt(2.0))[..., None]
    return better, worse


def _reading(p_for, p_against) -> np.ndarray:
    return decide(p_for, p_against)[1]


def _paper_means(rng, shape, paper_runs: int, distribution: str) -> np.ndarray:
    """Means over ``paper_runs`` runs of a method of the paper's, each run a shared and an own draw as ours
    (the paper's methods unpaired: each mean its own runs), summed a run at a time to stay small."""
    total = np.zeros(shape)
    for _ in range(paper_runs):
        total += noise(distribution, rng, shape) + noise(distribution, rng, shape)
    return total / paper_runs


def _told(paper_runs: int, exact: bool) -> PaperRuns:
    """The runs the test is told stand behind the paper's numbers (``exact``: none, the rule before)."""
    return PaperRuns(math.inf, False, "taken as exact") if exact else PaperRuns(paper_runs, True, "simulated")


def order_case(runs, distribution, truth, guards, effect, checks=1, paper_gain=None, others=0.0, paper_runs=None,
               exact=False) -> Case:
    """A reading of ``checks`` paired checks: the first at ``effect``, the rest at ``others`` (an
    intersection-union rule is at its worst with one check null and the rest strong).  ``paper_gain``: the
    paper's true gain at every check, its two numbers means of ``paper_runs`` runs each (``exact``: tested as
    if exact, the rule before)."""
    def draw(rng, reps):
        gains = [effect] + [others] * (checks - 1)
        better, worse = _pairs(rng, reps, runs, distribution, gains)
        paper = None
        if paper_gain is not None:
            theirs = _paper_means(rng, (2, reps, checks), paper_runs, distribution)
            paper = Effect(theirs[0] + paper_gain * math.sqrt(2.0), theirs[1], _told(paper_runs, exact))
        tested = order_test(better, worse, lower_is_better=False, paper=paper)
        return _reading(tested.p_for, tested.p_against)

    name = "order" if paper_gain is None else "order, paper's size" + (" taken as exact (old rule)" if exact else "")
    return Case(name if checks == 1 else f"{name}: reading", runs, checks, distribution, truth, guards, effect, draw,
                exact, math.nan if paper_gain is None else paper_runs)


def ratio_case(runs, distribution, truth, guards, ratio, paper_runs, exact=False) -> Case:
    """A claimed ratio of means (lower is better: the paper's true 0.5, ours ``ratio``; a run's coefficient of
    variation 0.1 sqrt 2): the size tested as Fieller's linear form, the paper's two numbers means of
    ``paper_runs`` runs each (``exact``: tested as if exact)."""
    def draw(rng, reps):
        shared = noise(distribution, rng, (reps, runs))
        worse = 10.0 * (1 + 0.1 * (shared + noise(distribution, rng, (reps, runs))))
        better = ratio * 10.0 * (1 + 0.1 * (shared + noise(distribution, rng, (reps, runs))))
        theirs = 10.0 * (1 + 0.1 * _paper_means(rng, (2, reps), paper_runs, distribution))
        paper = Effect(0.5 * theirs[0], theirs[1], _told(paper_runs, exact), "ratio")
        tested = order_test(better, worse, lower_is_better=True, paper=paper)
        return _reading(tested.p_for[..., None], tested.p_against[..., None])

    name = "order, paper's ratio" + (" taken as exact (old rule)" if exact else "")
    return Case(name, runs, 1, distribution, truth, guards, ratio, draw, exact, paper_runs)


def mcnemar_case(runs, truth, guards, wins, losses, paper=None, paper_runs=None, both=0.0, exact=False) -> Case:
    """Paired yes/no outcomes: a run is won by the claimed-better method alone with probability ``wins``,
    lost with ``losses``, won by both with ``both``, lost by both otherwise (``effect``: wins - losses).
    ``paper``: the paper's two true rates, its numbers each the share of ``paper_runs`` runs of its own
    (``exact``: tested as if exact)."""
    def draw(rng, reps):
        u = rng.random((reps, runs))
        both_won = (u >= wins + losses) & (u < wins + losses + both)
        better = ((u < wins) | both_won).astype(float)
        worse = (((u >= wins) & (u < wins + losses)) | both_won).astype(float)
        effect = None
        if paper is not None:
            rates = rng.binomial(paper_runs, paper, (reps, 2)) / paper_runs
            effect = Effect(rates[:, 0], rates[:, 1], _told(paper_runs, exact))
        tested = order_test(better, worse, lower_is_better=False, binary=True, paper=effect)
        return _reading(tested.p_for[..., None], tested.p_against[..., None])

    name = "order, yes/no" + ("" if paper is None else ", paper's size") + (" taken as exact (old rule)" if exact
                                                                           else "")
    return Case(name, runs, 1, "yes/no", truth, guards, round(wins - losses, 3), draw, exact,
                math.nan if paper is None else paper_runs)


def threshold_case(runs, distribution, truth, guards, effect) -> Case:
    """A median against a bound (the exact sign test), the true median ``effect`` sd above it."""
    def draw(rng, reps):
        values = noise(distribution, rng, (reps, runs)) - _median(distribution) + effect
        tested = sign_test(values, 0.0)
        return _reading(tested.p_above[..., None], tested.p_below[..., None])

    return Case("threshold (median)", runs, 1, distribution, truth, guards, effect, draw)


def bar_case(runs, distribution, truth, effect, rule: str, control=False, mirrored=False) -> Case:
    """One test of issue 61's bar (evidence/tables/non_inferiority.py) against a deterministic reference:
    ``rule`` "no worse" (a score at least the reference's less a margin) or "at most" (a count at most a
    bound), the median run ``effect`` sd on the clearing side of the bar (null: on it).  ``control``: the rule
    before, the one-sample t on the mean (its mean on the bar under the null), which a skewed spread misleads;
    ``mirrored``: the noise's skew turned the other way (a score's tail toward low values)."""
    margin, bound = 0.5, 1.5

    def draw(rng, reps):
        sign = -1.0 if mirrored else 1.0
        centred = sign * noise(distribution, rng, (reps, runs))  # mean 0; the control's null puts the mean on the bar
        centred = centred if control else centred - sign * _median(distribution)  # median 0: the rule's null
        if rule == "no worse":
            ours, reference = centred - margin + effect, np.zeros((reps, runs))
            cleared = (mean_test(ours - reference + margin).p_above if control
                       else no_worse(ours, reference, False, margin)) < INFERENCE.alpha
        else:
            ours = centred + bound - effect
            cleared = (mean_test(ours, bound).high <= bound) if control else at_most(ours, bound) < INFERENCE.alpha
        return np.where(cleared, REPRODUCED, NOT_REPRODUCED)

    name = f"bar: {rule}" + (", the t on the mean (rule before)" if control else " (median run, sign test)")
    return Case(name + (", skew mirrored" if mirrored else ""), runs, 1, distribution, truth, "reproduced", effect,
                draw, control)


def _lognormal_moments() -> tuple[float, float]:
    """The mean and standard deviation of a lognormal of log-scale 0 and ``LOGNORMAL_SIGMA``."""
    s2 = LOGNORMAL_SIGMA ** 2
    return math.exp(s2 / 2), math.sqrt((math.exp(s2) - 1) * math.exp(s2))


def _median(distribution: str) -> float:
    """The median of :func:`noise`'s draws (the lognormal's is 1 before standardising)."""
    if distribution != "lognormal":
        return 0.0
    mean, sd = _lognormal_moments()
    return (1.0 - mean) / sd


def cell_case(runs, distribution, truth, guards, mean, paper_runs=None) -> Case:
    """A published mean of 1 against our runs of true mean ``mean`` and coefficient of variation 0.2
    (:func:`~replication.evidence.verdict.cell_test`, the test :func:`judge_value` decides by: equivalence
    within +-10 %)."""
    def draw(rng, reps):
        p_for, p_against = cell_test(1.0, mean + 0.2 * noise(distribution, rng, (reps, runs)), paper_runs=paper_runs)
        return _reading(p_for[..., None], p_against[..., None])

    return Case("published value", runs, 1, distribution, truth, guards, round((mean - 1.0) / 0.2, 3), draw)


def rate_case(runs, truth, guards, rate, paper=0.8) -> Case:
    """A published rate of ``paper`` (+-10 %: [0.72, 0.88]) against runs succeeding at ``rate``, judged by
    :func:`~replication.evidence.verdict.judge_value` (exact binomial test, Clopper-Pearson equivalence)."""
    codes = np.array([OUTCOMES.index(judge_value(paper, np.r_[np.ones(k), np.zeros(runs - k)],
                                                 Quantity("binary", 0.0, 1.0)).outcome) for k in range(runs + 1)])

    def draw(rng, reps):
        return codes[rng.binomial(runs, rate, reps)]

    return Case("published rate", runs, 1, "yes/no", truth, guards, round((rate - paper) / paper, 3), draw)


def band_case(runs, truth, guards, rate) -> Case:
    """bis_pf's stability rating ('good': at most 1.5 failures in 10) against runs failing at ``rate``."""
    bands = stability_bands()

    def draw(rng, reps):
        failures = rng.binomial(runs, rate, reps)
        return np.array([OUTCOMES.index(judge_band("good", int(k), runs, bands).outcome) for k in failures])

    return Case("rating (band)", runs, 1, "yes/no", truth, guards, rate, draw)


def _cube(rng, reps, distribution, lead, methods=7, sequences=6, runs=5, spread=0.1):
    """Scores (reps x sequences x runs x methods, higher is better) of methods that differ per sequence
    (sd ``spread``) and per run (sd ``spread``, common random numbers), method 0 ahead of the rest by
    ``lead`` (the rest level)."""
    per_sequence = spread * noise(distribution, rng, (reps, sequences, 1, methods))
    shared = spread * noise(distribution, rng, (reps, sequences, runs, 1))
    own = spread * noise(distribution, rng, (reps, sequences, runs, methods))
    scores = per_sequence + shared + own
    scores[..., 0] += lead
    return scores


def best_case(distribution, truth, guards, lead, control=False) -> Case:
    """'Method 0 is best' over 7 methods x 6 sequences x 5 runs (hspf at paper scale), method 0 ahead of
    the others by ``lead`` (in sd of a sequence's difference, sqrt(2) x 0.1 x sqrt(1 + 1/5))."""
    unit = 0.1 * math.sqrt(2.0 * (1 + 1 / 5))

    def draw(rng, reps):
        scores = _cube(rng, reps, distribution, lead * unit)
        if control:
            return np.array([_old_best(s) for s in scores])
        tested = best_test(scores.mean(axis=2), 0, lower_is_better=False)
        return _reading(tested.p_for, tested.p_against)

    name = "best (P(best), old rule)" if control else "best"
    return Case(name, 5, 6, distribution, truth, guards, lead, draw, control)


def _old_best(scores: np.ndarray) -> int:
    found = rank(scores, list(range(scores.shape[-1])), list(range(scores.shape[0])), lower_is_better=False)
    p = float(found.p_best[found.methods.index(0)])
    return REPRODUCED if p >= 0.95 else NOT_REPRODUCED if p <= 0.05 else OUTCOMES.index(Outcome.INCONCLUSIVE)


def rank_case(distribution, control=False) -> Case:
    """A rank interval's coverage: 7 methods 0.2 sd apart (true ranks distinct but close) over 6 sequences x
    5 runs, each sequence favouring each method by its own draw; a replication errs where the middle
    method's interval misses its true rank, 4."""
    unit = 0.1 * math.sqrt(2.0 * (1 + 1 / 5))

    def draw(rng, reps):
        scores = _cube(rng, reps, distribution, 0.0)
        scores += unit * 0.2 * np.arange(7)[::-1]  # method 0 best, true rank k + 1
        if control:
            found = [rank(s, list(range(7)), list(range(6)), lower_is_better=False) for s in scores]
            low, high = np.array([_percentile_rank(f, 3) for f in found]).T
        else:
            low, high = rank_set(scores.mean(axis=2), 3, lower_is_better=False)
        return np.where((low <= 4) & (4 <= high), REPRODUCED, NOT_REPRODUCED)

    name = "rank interval (bootstrap percentiles, old rule)" if control else "rank interval (rank set)"
    return Case(name, 5, 6, distribution, "null", "misses the true rank", 0.2, draw, control)


def _percentile_rank(found, method: int) -> tuple[int, int]:
    """The old rank interval: the 2.5 and 97.5 percentiles of the two-level bootstrap's rank distribution."""
    cumulative = np.cumsum(found.rank_probability[found.methods.index(method)])
    return tuple(int(np.searchsorted(cumulative, q - 1e-9)) + 1 for q in (0.025, 0.975))


def bca_case(runs, distribution, truth, guards, checks, effect) -> Case:
    """The rule of before: each check's 95 % BCa interval of the paired mean; reproduced when every interval
    lies above zero, not reproduced when any lies at or below it (no correction)."""
    def draw(rng, reps):
        codes = []
        for chunk in np.array_split(np.arange(reps), max(1, reps * checks * runs // 20_000)):
            better, worse = _pairs(rng, len(chunk), runs, distribution, [effect] * checks)
            interval = stats.bootstrap((better - worse,), np.mean, axis=-1, vectorized=True, method="BCa",
                                       n_resamples=999, random_state=rng).confidence_interval
            low, high = np.nan_to_num(interval.low, nan=-np.inf), np.nan_to_num(interval.high, nan=np.inf)
            codes.append(np.select([(high <= 0).any(axis=-1), (low > 0).all(axis=-1)], [NOT_REPRODUCED, REPRODUCED],
                                   2))
        return np.concatenate(codes)

    name = "order (BCa, old rule)" if checks == 1 else "order: reading (BCa, any check fails, old rule)"
    return Case(name, runs, checks, distribution, truth, guards, effect, draw, control=True)


def robustness_case(runs, distribution, truth, guards, effect, alternatives=4) -> Case:
    """A claim's multiverse: a default universe and ``alternatives`` others on the same data (each adds its
    own noise, half the runs' own, and ``effect`` sd to the deciding paired difference; the default sits at
    0.5 sd, where verdicts of few runs flip often); the verdict depends on the reading where an alternative
    moves it (:func:`~replication.evidence.robustness.depends`).  Under no effect "depends on the reading"
    is wrong; under an effect of -1 sd (the choice turns the claim's 0.5 sd gain into -0.5) it is right."""
    def draw(rng, reps):
        better, worse = _pairs(rng, reps, runs, distribution, [0.5])  # the default universe, reps x 1 x runs
        moved = better + 0.5 * noise(distribution, rng, (reps, alternatives, runs)) + effect * math.sqrt(2.0)
        default, other = (order_test(b, worse, lower_is_better=False) for b in (better, moved))
        flipped = _reading(other.p_for[..., None], other.p_against[..., None]) != \
            _reading(default.p_for[..., None], default.p_against[..., None])
        shift = mean_test(moved - better)  # each alternative's paired effect on the deciding statistic
        adjusted = holm(np.minimum(1.0, 2 * np.minimum(shift.p_above, shift.p_below)))
        return np.where(depends(adjusted, flipped).any(axis=-1), NOT_REPRODUCED, REPRODUCED)

    return Case("multiverse robustness", runs, alternatives, distribution, truth, guards, effect, draw)


GROWTH_X = np.repeat([4.0, 9.0, 16.0, 25.0, 36.0, 64.0], 3)  # bis_pf_scaling: 6 numbers of targets x 3 runs
GROWTH_BOUND = 1.5  # bis_pf.linear's at_most
PARETO_SETTINGS, PARETO_RUNS = 30, 20  # hspf_ungm_sweep: 6 NI x 5 HMS, 20 runs at paper scale


def growth_case(distribution, truth, guards, exponent, spread=0.1) -> Case:
    """A time ~ M^``exponent`` over :data:`GROWTH_X`, each point with its own multiplicative noise of log-sd
    ``spread``, against :data:`GROWTH_BOUND` (null: the exponent at the bound)."""
    def draw(rng, reps):
        logs = exponent * np.log(GROWTH_X) + spread * noise(distribution, rng, (reps, len(GROWTH_X)))
        slope = log_log_slope(GROWTH_X, np.exp(logs), GROWTH_BOUND)
        return _reading(slope.p_below[:, None], slope.p_above[:, None])
    return Case("growth", len(GROWTH_X), 1, distribution, truth, guards, exponent, draw)


def pareto_case(distribution, truth, guards, rival, others=3.0) -> Case:
    """The chosen setting against :data:`PARETO_SETTINGS` - 1 others on two metrics (lower is better) over
    :data:`PARETO_RUNS` runs on common random numbers: the first rival ahead by ``rival`` (standard deviations
    of a run's difference, per metric), every other behind by ``others`` on one metric and ahead by as much
    on the other (a trade-off, as Figure 3's grid). Null for "reproduced": a rival equal on both, (0, 0);
    null for "not reproduced": a rival equal on one and ahead on the other, at the edge of dominance."""
    def draw(rng, reps):
        k = PARETO_SETTINGS - 1
        shift = np.tile(np.array([others, -others]), (k, 1))
        shift[0] = rival
        shape = (reps, k, PARETO_RUNS, 2)
        shared = noise(distribution, rng, (reps, 1, PARETO_RUNS, 2))
        chosen = shared + noise(distribution, rng, shape)
        other = shared + noise(distribution, rng, shape) - (shift * math.sqrt(2.0))[None, :, None, :]
        tested = dominance(chosen, other)
        return _reading(tested.p_for, tested.p_against)
    return Case("pareto", PARETO_RUNS, PARETO_SETTINGS - 1, distribution, truth, guards, float(np.max(rival)), draw)


def cases(runs=RUNS, distributions=DISTRIBUTIONS) -> list[Case]:
    """Every row of the calibration table."""
    found = []
    for n in runs:
        for d in distributions:
            found += [order_case(n, d, "null", "reproduced", 0.0), order_case(n, d, "null", "not reproduced", 0.0)]
            found += [order_case(n, d, "effect", "reproduced", e) for e in EFFECTS]
            found += [threshold_case(n, d, "null", "reproduced", 0.0), threshold_case(n, d, "null", "not reproduced",
                                                                                      0.0)]
            found += [threshold_case(n, d, "effect", "reproduced", e) for e in EFFECTS]
            found += [cell_case(n, d, "null", "reproduced", 1.1), cell_case(n, d, "null", "reproduced", 0.9),
                      cell_case(n, d, "null", "not reproduced", 1.0),
                      cell_case(n, d, "effect", "reproduced", 1.0)]
            found += [cell_case(n, d, "effect", "not reproduced", 1.0 + 0.2 * e) for e in EFFECTS]
            for k in CHAINS:
                found += [order_case(n, d, "null", "reproduced", 0.0, checks=k, others=3.0),
                          order_case(n, d, "null", "not reproduced", 0.0, checks=k),
                          order_case(n, d, "null", "not reproduced", 1.0, checks=k, paper_gain=1.0, others=1.0,
                                     paper_runs=n),
                          order_case(n, d, "effect", "reproduced", 1.0, checks=k, others=1.0)]
        found += [robustness_case(n, d, "null", "depends on the reading", 0.0) for d in distributions]
        found += [robustness_case(n, d, "effect", "depends on the reading", -1.0) for d in distributions]
        found += [mcnemar_case(n, "null", "reproduced", 0.2, 0.2), mcnemar_case(n, "null", "not reproduced", 0.2, 0.2),
                  mcnemar_case(n, "effect", "reproduced", 0.5, 0.0)]
        found += size_cases(n, distributions)
        found += criterion_cases(n, distributions)
        found += [rate_case(n, "null", "reproduced", 0.72), rate_case(n, "null", "reproduced", 0.88),
                  rate_case(n, "null", "not reproduced", 0.8), rate_case(n, "effect", "reproduced", 0.8)]
    for n in (5, 10):
        found += [band_case(n, "null", "not reproduced", 0.15), band_case(n, "null", "reproduced", 0.16)]
        for rule, d, mirrored in itertools.product(BAR_RULES, distributions, (False, True)):
            found += [bar_case(n, d, "null", 0.0, rule, mirrored=mirrored),
                      bar_case(n, d, "null", 0.0, rule, control=True, mirrored=mirrored)]
            found += [bar_case(n, d, "effect", e, rule, mirrored=mirrored) for e in EFFECTS]
    for d in distributions:
        found += [best_case(d, "null", "reproduced", 0.0), best_case(d, "null", "not reproduced", 0.0),
                  best_case(d, "effect", "reproduced", 1.0)]
    found += [rank_case(d) for d in distributions] + [rank_case("normal", control=True)]
    for n in (5, 20):
        found += [bca_case(n, d, "null", "reproduced", 1, 0.0) for d in distributions]
        found += [bca_case(n, d, "null", "not reproduced", 9, 0.0) for d in distributions]
    found += [best_case("normal", "null", "not reproduced", 0.14, control=True)]
    for d in distributions:
        found += [growth_case(d, "null", "reproduced", GROWTH_BOUND), growth_case(d, "null", "not reproduced", GROWTH_BOUND),
                  growth_case(d, "effect", "reproduced", 1.0)]
        found += [pareto_case(d, "null", "reproduced", (0.0, 0.0)), pareto_case(d, "null", "not reproduced", (0.0, 1.0)),
                  pareto_case(d, "effect", "reproduced", (-1.0, -1.0))]
    return found


def criterion_case(runs, distribution, truth, key, paper_runs) -> Case:
    """How often replication criterion ``key`` (:data:`~replication.evidence.criteria.CRITERION`) says the
    replication succeeded, through :func:`~replication.evidence.comparisons.order_test` and the criterion's
    own function: ``truth = "effect"``: the paper's effect true in its runs and ours, 1 standard deviation of a
    run's difference; ``"null"``: no effect in either, the paper's two numbers means of ``paper_runs`` runs
    around one value (where they do not favour the claim it quotes no size, and nothing succeeds)."""
    gain = 1.0 if truth == "effect" else 0.0

    def draw(rng, reps):
        better, worse = _pairs(rng, reps, runs, distribution, [gain])
        theirs = _paper_means(rng, (2, reps, 1), paper_runs, distribution)
        paper = Effect(theirs[0] + gain * math.sqrt(2.0), theirs[1], _told(paper_runs, False))
        tested = order_test(better, worse, lower_is_better=False, paper=paper)
        success = np.zeros((reps, 1), dtype=bool)
        if tested.replication is not None:
            favours = paper.gain(lower_is_better=False) > 0
            success = favours & ~tested.tied & CRITERION[key].met(tested.replication)
        return np.where(success[:, 0], REPRODUCED, NOT_REPRODUCED)

    return Case(CRITERION[key].name, runs, 1, distribution, truth, SUCCESS, gain, draw, paper_runs=paper_runs,
                criterion=True)


def criterion_cases(runs: int, distributions=DISTRIBUTIONS) -> list[Case]:
    """The rows of each of :data:`CALIBRATED_CRITERIA` at our ``runs``, the paper's numbers means of each count
    of :data:`PAPER_RUNS` and of as many runs as ours, under no effect and the paper's effect true."""
    return [criterion_case(runs, d, truth, key, m) for key in CALIBRATED_CRITERIA for m in sorted({*PAPER_RUNS, runs})
            for d in distributions for truth in ("null", "effect")]


def size_cases(runs: int, distributions=DISTRIBUTIONS) -> list[Case]:
    """The rows of a paper's size at our ``runs``: the paper's numbers means of each count of
    :data:`PAPER_RUNS` and of as many runs as ours; the null (ours the paper's true effect) and ours at half
    its size, for a difference, a ratio and yes/no outcomes (40 pp apart as 45 % and 5 %, and as fusion_pf's
    95 % and 55 %); and the rule before (the paper's numbers, means of as many runs as ours, taken as exact)."""
    found = []
    for m in sorted({*PAPER_RUNS, runs}):
        for d in distributions:
            found += [order_case(runs, d, "null", "not reproduced", 1.0, paper_gain=1.0, paper_runs=m),
                      order_case(runs, d, "effect", "not reproduced", 0.5, paper_gain=1.0, paper_runs=m),
                      ratio_case(runs, d, "null", "not reproduced", 0.5, m),
                      ratio_case(runs, d, "effect", "not reproduced", 0.75, m)]
        found += [mcnemar_case(runs, "null", "not reproduced", 0.45, 0.05, (0.45, 0.05), m),
                  mcnemar_case(runs, "effect", "not reproduced", 0.25, 0.05, (0.45, 0.05), m),
                  mcnemar_case(runs, "null", "not reproduced", 0.4, 0.0, (0.95, 0.55), m, both=0.55),
                  mcnemar_case(runs, "effect", "not reproduced", 0.2, 0.0, (0.95, 0.55), m, both=0.55)]
    return found + [order_case(runs, "normal", "null", "not reproduced", 1.0, paper_gain=1.0, paper_runs=runs,
                               exact=True),
                    ratio_case(runs, "normal", "null", "not reproduced", 0.5, runs, exact=True),
                    mcnemar_case(runs, "null", "not reproduced", 0.45, 0.05, (0.45, 0.05), runs, exact=True)]


def simulate(case: Case, replications: int, seed: int = SEED) -> dict:
    """One row: the share of replications giving the verdict the case guards, with its Monte Carlo error."""
    name = repr((case.test, case.runs, case.checks, case.distribution, case.truth, case.guards, case.effect)
                + ((case.paper_runs,) if math.isfinite(case.paper_runs) else ()))
    rng = np.random.default_rng([seed, zlib.crc32(name.encode())])
    codes = case.draw(rng, replications)
    guarded = REPRODUCED if case.guards in ("reproduced", "robust", SUCCESS) else NOT_REPRODUCED  # or "depends"
    rate = float(np.mean(codes == guarded))
    mc_se = math.sqrt(max(rate * (1 - rate), 1e-12) / replications)
    null = case.truth == "null"
    return {"test": case.test, "runs": case.runs, "checks": case.checks, "distribution": case.distribution,
            "truth": case.truth, "guards": case.guards, "effect": case.effect, "paper_runs": case.paper_runs,
            "rate": rate, "mc_se": mc_se,
            "wrong_rate": rate if null else float(np.mean(codes == (NOT_REPRODUCED if guarded == REPRODUCED
                                                                     else REPRODUCED))),
            "power": math.nan if null else rate,
            "holds": (rate <= INFERENCE.alpha + 2 * mc_se) if null and not case.criterion else None,
            "control": case.control, "criterion": case.criterion, "replications": replications}


def calibrate(replications: int = REPLICATIONS, runs=RUNS, distributions=DISTRIBUTIONS, progress=None) -> pd.DataFrame:
    """The calibration table (``reports/calibration.csv``): one row per case of :func:`cases`."""
    rows = []
    todo = cases(runs, distributions)
    for i, case in enumerate(todo):
        rows.append(simulate(case, replications))
        if progress:
            progress(i + 1, len(todo))
    return pd.DataFrame(rows, columns=COLUMNS)
