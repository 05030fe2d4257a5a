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

Both work on arrays whose last axis is the runs, so the calibration runs the
very same code on thousands of simulated experiments.
"""

from dataclasses import dataclass

import numpy as np
from scipy import stats

from replication.evidence.inference import (
    Test,
    detectable,
    mean_test,
    paired_binary_test,
)


@dataclass(frozen=True)
class Effect:
    """The paper's numbers for the claimed-better and the claimed-worse method, and how their gap is read:
    ``difference`` (better - worse) or ``ratio`` (better / worse)."""

    better: float
    worse: float
    kind: str = "difference"

    def gain(self, lower_is_better: bool) -> float:
        """The paper's gain in the claim's orientation (positive: the paper's effect favours the claim)."""
        return self.worse - self.better if lower_is_better else self.better - self.worse

    @property
    def ratio(self) -> float:
        return self.better / self.worse

    def __str__(self) -> str:
        if self.kind == "ratio":
            return f"ratio {self.ratio:.3g} ({self.better:g} / {self.worse:g})"
        return f"{self.better - self.worse:+.3g} ({self.better:g} - {self.worse:g})"


@dataclass(frozen=True)
class OrderTest:
    """The tests of one ordered pair of methods over paired runs (arrays over leading batch axes)."""

    gain: Test  # the direction: its mean and interval, p_above = p_for
    size: Test | None  # the paper's size: p_below = the evidence that ours falls short of it
    spread: np.ndarray  # the standard deviation of the per-run gain

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
    is the size tested against ours (a paper whose numbers do not favour the claim quotes no size)."""
    better, worse = np.asarray(better, dtype=float), np.asarray(worse, dtype=float)
    gain = (worse - better if lower_is_better else better - worse) + np.asarray(allowed)[..., None]
    direction = paired_binary_test(np.sign(gain)) if binary else mean_test(gain)
    size = None
    if paper is not None and paper.gain(lower_is_better) > 0:
        if binary:
            size = _binary_size(gain, paper.gain(lower_is_better))
        elif paper.kind == "ratio":
            short = paper.ratio * worse - better if lower_is_better else better - paper.ratio * worse
            size = mean_test(short)
        else:
            size = mean_test(gain, paper.gain(lower_is_better))
    return OrderTest(direction, size, gain.std(axis=-1, ddof=1) if gain.shape[-1] > 1 else np.full(gain.shape[:-1],
                                                                                                   np.nan))


def _binary_size(gain: np.ndarray, paper_gain: float) -> Test:
    """Paired yes/no outcomes against the paper's difference of rates ``paper_gain``: the difference
    p10 - p01 is at most p10, so its falling short of the paper's is shown exactly (if conservatively) when
    the runs the claimed-better method alone got right are too few for a rate p10 >= ``paper_gain``."""
    n = gain.shape[-1]
    wins = (gain > 0).sum(axis=-1)
    p_below, p_above = (tail(wins, n, min(paper_gain, 1.0)) for tail in (stats.binom.cdf, stats.binom.sf))
    mean = gain.mean(axis=-1)
    return Test(mean, np.full(mean.shape, np.nan), np.full(mean.shape, np.nan), p_above, p_below, n,
                "exact binomial bound")


def best_test(per_sequence, index: int, lower_is_better: bool) -> OrderTest:
    """``per_sequence`` (sequences x methods: each method's mean over its runs on each sequence; leading
    batch axes allowed): method ``index`` against every other, the paired t-test over the sequences (a
    sequence-level t: the sequences are the sample, the runs within them average out).  The result's
    arrays run over the competitors (last axis), in the methods' order without ``index``."""
    scores = np.moveaxis(np.asarray(per_sequence, dtype=float), -1, -2)  # ... x methods x sequences
    others = np.delete(scores, index, axis=-2)
    return order_test(scores[..., index:index + 1, :], others, lower_is_better)
