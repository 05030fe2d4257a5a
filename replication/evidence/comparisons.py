"""The tests behind a claim that one method beats another: paired on common random numbers, in the claimed
direction, and against the size of the paper's own effect where it quotes one.

A check's *gain* is the per-run difference oriented so that a positive value
favours the claim (the claimed-worse method's error minus the claimed-better
one's, or the better one's score minus the worse one's).  Its tests:

* ``p_for``: the gain's mean is positive (Student's paired t; McNemar's exact
  test for yes/no outcomes) -- the evidence for "reproduced";
* ``p_against``: where the paper's two numbers are known (:class:`Effect`), the
  gain falls short of the paper's own gain, as a difference or as a ratio
  (a ratio r = theirs_better / theirs_worse is tested as the mean of
  ``r * worse - better`` being negative, Fieller's linear form); else the gain
  is negative -- the evidence for "not reproduced".

The paper's gain is itself an estimate, from the runs :class:`Effect` says
(:mod:`replication.evidence.original`): the size test adds its noise to ours
(:func:`size_test`).  Where every run of both methods gives one value (both at
a floor or a ceiling) nothing is tested: the runs decide nothing about the paper.

Both work on arrays whose last axis is the runs, so the calibration runs the
very same code on thousands of simulated experiments.
"""

import math
from dataclasses import dataclass, replace

import numpy as np

from replication.evidence.criteria import Replication
from replication.evidence.inference import (
    Test,
    detectable,
    mean_test,
    paired_binary_test,
    t_test,
)
from replication.evidence.original import PaperRuns
from replication.evidence.settings import INFERENCE


@dataclass(frozen=True)
class Effect:
    """The paper's numbers for the claimed-better and the claimed-worse method, and how their gap is read:
    ``difference`` (better - worse) or ``ratio`` (better / worse)."""

    better: float
    worse: float
    runs: PaperRuns  # the runs behind each of the two numbers (n = math.inf: taken as exact)
    kind: str = "difference"

    def gain(self, lower_is_better: bool) -> float:
        """The paper's gain in the claim's orientation (positive: the paper's effect favours the claim)."""
        return self.worse - self.better if lower_is_better else self.better - self.worse

    @property
    def ratio(self) -> float:
        return self.better / self.worse

    def __str__(self) -> str:
        if self.kind == "ratio":
            return f"ratio {self.ratio:.3g} ({self.better:g} / {self.worse:g}; {self.runs})"
        return f"{self.better - self.worse:+.3g} ({self.better:g} - {self.worse:g}; {self.runs})"


@dataclass(frozen=True)
class OrderTest:
    """The tests of one ordered pair of methods over paired runs (arrays over leading batch axes)."""

    gain: Test  # the direction: its mean and interval, p_above = p_for
    size: Test | None  # the paper's size: p_below = the evidence that ours falls short of it
    spread: np.ndarray  # the standard deviation of the per-run gain
    tied: np.ndarray  # every run of both methods gives one value: nothing is tested
    bound: Test  # whose upper bound the gain's interval shows: the size test's where in the gain's units
    replication: Replication | None = None  # the paper's effect and ours on one scale, where it quotes a size

    @property
    def p_for(self) -> np.ndarray:
        return self.gain.p_above

    @property
    def p_against(self) -> np.ndarray:
        return self.gain.p_below if self.size is None else self.size.p_below

    @property
    def detectable(self) -> float:
        """The smallest mean gain these runs detect with 80 % power (one check, one-sided 5 %)."""
        return detectable(float(np.mean(self.spread)), self.gain.runs)


def order_test(better, worse, lower_is_better: bool, binary: bool = False, allowed=0.0,
               paper: Effect | None = None) -> OrderTest:
    """The paired tests that ``better`` beats ``worse`` (per-run values, run r of each on the same data;
    last axis: runs).  ``binary``: yes/no outcomes (0 or 1 per run; McNemar).  ``allowed``: a margin in
    the claim's favour ("no worse than by more than that").  ``paper``: the paper's two numbers, whose gap
    is the size tested against ours (a paper whose numbers do not favour the claim quotes no size; arrays
    over the batch axes where simulated).  Where every run of both methods gives one value, nothing is
    tested (``tied``)."""
    better, worse = np.asarray(better, dtype=float), np.asarray(worse, dtype=float)
    gain = (worse - better if lower_is_better else better - worse) + np.asarray(allowed)[..., None]
    direction = paired_binary_test(np.sign(gain)) if binary else mean_test(gain)
    tied = ((better == better[..., :1]) & (worse == better[..., :1])).all(axis=-1)
    size, bound = None, direction
    favours = paper is not None and np.asarray(paper.gain(lower_is_better)) > 0  # per experiment when simulated
    if np.any(favours):  # else no size: the direction's p_below (NaN where tied) stands
        found = size_test(gain, better, worse, lower_is_better, binary, paper)
        sized = favours & ~tied
        size = replace(found, **{k: np.where(sized, getattr(found, k), getattr(direction, k))
                                 for k in ("p_above", "p_below", "high")})
        bound = direction if paper.kind == "ratio" else size
        replication = effects(gain, better, worse, lower_is_better, binary, paper, direction.p_above)
    spread = gain.std(axis=-1, ddof=1) if gain.shape[-1] > 1 else np.full(gain.shape[:-1], np.nan)
    return OrderTest(direction, size, spread, tied, bound, replication if np.any(favours) else None)


def size_test(gain, better, worse, lower_is_better: bool, binary: bool, paper: Effect) -> Test:
    """Ours against the paper's gain, both estimates: p_below, that ours falls short of it.

    The paper's n_paper = ``paper.runs.n`` runs per method are taken as unpaired (nothing says its methods
    shared random numbers), their spread as ours (the papers give none).  Each statistic is referred to t
    with n_ours - 1 degrees of freedom (the fewest the variances from our runs can have: conservative):

    * a difference: our mean gain minus the paper's over sqrt(var(gain) / n_ours + (var(better) +
      var(worse)) / n_paper), a Welch-type t of our paired runs against the paper's two unpaired means;
    * a ratio r = theirs_better / theirs_worse: Fieller's linear form, the mean of ``r * worse - better``
      (oriented), its variance ours plus the paper's ratio's by the delta method, (r0 mean(worse))^2
      (cv(better)^2 + cv(worse)^2) / n_paper: our coefficients of variation carried to the paper's means (a
      ratio is scale-free), at r0, the ratio ours and the paper's share under the null (their mean weighted
      by their run counts: a restricted estimate, as a pooled rate is in the two-sample test of rates);
    * yes/no outcomes: our paired difference of rates minus the paper's difference of two independent rates,
      each variance at rates restricted to the null, both gaps the pooled gap d0 (weighted by run counts):
      ours (s - d0^2) / n_ours, s the share of discordant runs (at least |d0|); the paper's
      (a (1 - a) + b (1 - b)) / n_paper, a and b its two rates moved to d0 apart, their sum kept.

    The paper's noise is estimated from ours, which heavy tails understate (the paper's runs are not seen to
    widen it): the test runs at the size-corrected level ``INFERENCE.size_alpha`` that the calibration sets,
    its p_below said on the 5 % scale (times alpha / size_alpha).  Its interval is ours with both noises, each
    bound one-sided at that level: a paper's gap beyond its upper bound is what the test rejects.
    ``paper.runs.n`` = ``math.inf`` is the paper's number taken as exact (the rule used before)."""
    n, n_paper = gain.shape[-1], paper.runs.n
    theirs_weight = 1.0 if math.isinf(n_paper) else n_paper / (n + n_paper)  # the paper's in a pooled value
    estimate, reference = gain.mean(axis=-1), paper.gain(lower_is_better)
    with np.errstate(all="ignore"):  # one run: no spread, no test
        if binary:
            wins, losses = (gain > 0).mean(axis=-1), (gain < 0).mean(axis=-1)
            pooled = (1 - theirs_weight) * (wins - losses) + theirs_weight * reference
            ours = (np.maximum(wins + losses, np.abs(pooled)) - pooled ** 2) / n
            total = paper.better + paper.worse
            rates = [np.clip((total + side * pooled) / 2, 0.0, 1.0) for side in (1, -1)]
            variance = ours + sum(rate * (1 - rate) for rate in rates) / n_paper
        elif paper.kind == "ratio":
            ratio = np.asarray(paper.ratio)[..., None]  # over the runs
            short = ratio * worse - better if lower_is_better else better - ratio * worse
            estimate, reference = short.mean(axis=-1), 0.0
            pooled = (1 - theirs_weight) * better.mean(axis=-1) / worse.mean(axis=-1) + theirs_weight * paper.ratio
            cv2 = better.var(axis=-1, ddof=1) / better.mean(axis=-1) ** 2 + worse.var(
                axis=-1, ddof=1) / worse.mean(axis=-1) ** 2
            variance = short.var(axis=-1, ddof=1) / n + (pooled * worse.mean(axis=-1)) ** 2 * cv2 / n_paper
        else:
            variance = gain.var(axis=-1, ddof=1) / n + (better.var(axis=-1, ddof=1) + worse.var(
                axis=-1, ddof=1)) / n_paper
    form = "Fieller's linear form, t" if paper.kind == "ratio" and not binary else "t"
    found = t_test(estimate, np.sqrt(variance), n - 1, n, reference,
                   f"{form} with the paper's own noise ({paper.runs})", INFERENCE.size_alpha)
    return replace(found, p_below=np.minimum(1.0, found.p_below * (INFERENCE.alpha / INFERENCE.size_alpha)))


def effects(gain, better, worse, lower_is_better: bool, binary: bool, paper: Effect, p_direction) -> Replication:
    """The paper's effect and ours on one scale, oriented so that positive favours the claim, each with its
    standard error (the paper's from our per-run spread at its run count, as :func:`size_test` takes it, but
    unrestricted by a null), for the criteria of :mod:`replication.evidence.criteria`:

    * a difference: our mean gain, se sqrt(var(gain) / n); the paper's gap, se sqrt((var(better) +
      var(worse)) / n_paper); the per-run spread sd(gain);
    * a ratio: log(better / worse) of the means (negated where lower is better), ours by the delta method on
      the paired runs, var(better / mean(better) - worse / mean(worse)) / n, the paper's (cv(better)^2 +
      cv(worse)^2) / n_paper; the spread that of the per-run term;
    * yes/no outcomes: the difference of rates, ours paired, (s - d^2) / n with s the discordant share; the
      paper's two independent binomial rates, (a (1 - a) + b (1 - b)) / n_paper."""
    n, n_paper = gain.shape[-1], paper.runs.n
    with np.errstate(all="ignore"):  # one run, or no spread: NaN, and no criterion is met
        if binary:
            ours = gain.mean(axis=-1)
            ours_var = (np.abs(gain).mean(axis=-1) - ours ** 2) / n
            a, b = np.asarray(paper.better), np.asarray(paper.worse)
            theirs, theirs_var = paper.gain(lower_is_better), (a * (1 - a) + b * (1 - b)) / n_paper
            spread, scale = gain.std(axis=-1, ddof=1), "difference of rates"
        elif paper.kind == "ratio":
            sign = -1.0 if lower_is_better else 1.0
            mean_b, mean_w = better.mean(axis=-1), worse.mean(axis=-1)
            term = better / mean_b[..., None] - worse / mean_w[..., None]
            ours, ours_var = sign * np.log(mean_b / mean_w), term.var(axis=-1, ddof=1) / n
            cv2 = better.var(axis=-1, ddof=1) / mean_b ** 2 + worse.var(axis=-1, ddof=1) / mean_w ** 2
            theirs, theirs_var = sign * np.log(paper.ratio), cv2 / n_paper
            spread, scale = term.std(axis=-1, ddof=1), "log ratio"
        else:
            ours, ours_var = gain.mean(axis=-1), gain.var(axis=-1, ddof=1) / n
            theirs = paper.gain(lower_is_better)
            theirs_var = (better.var(axis=-1, ddof=1) + worse.var(axis=-1, ddof=1)) / n_paper
            spread, scale = gain.std(axis=-1, ddof=1), "difference"
    return Replication(scale, theirs, np.sqrt(theirs_var), ours, np.sqrt(ours_var), p_direction, n, n_paper,
                       paper.runs.stated, spread)


def best_test(per_sequence, index: int, lower_is_better: bool) -> OrderTest:
    """``per_sequence`` (sequences x methods: each method's mean over its runs on each sequence; leading
    batch axes allowed): method ``index`` against every other, the paired t-test over the sequences (a
    sequence-level t: the sequences are the sample, the runs within them average out).  The result's
    arrays run over the competitors (last axis), in the methods' order without ``index``."""
    scores = np.moveaxis(np.asarray(per_sequence, dtype=float), -1, -2)  # ... x methods x sequences
    others = np.delete(scores, index, axis=-2)
    return order_test(scores[..., index:index + 1, :], others, lower_is_better)
