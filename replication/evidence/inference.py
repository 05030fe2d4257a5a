"""The hypothesis tests behind every verdict, exact or at nominal level for the run counts used (scipy.stats).

Every decision is a one-sided test at :data:`INFERENCE.alpha` (5 %) in one direction:
``p_above`` is the p-value of "the true value is above the reference"
(H0: at or below it), ``p_below`` of "below" (H0: at or above).  The interval
of a :class:`Test` is the two-sided (1 - 2 INFERENCE.alpha) = 90 % interval whose each
bound is the one-sided 95 % bound, so a test rejects exactly when the
reference lies beyond the bound on its side.

* a mean of per-run values, or of paired per-run differences (common random
  numbers): Student's t (``scipy.stats.ttest_1samp``); at 5 runs it holds its
  level under normal, heavy-tailed and skewed per-run values of two
  interchangeable methods, where the BCa bootstrap does not
  (``reports/calibration.csv``);
* a median against a bound, or paired yes/no outcomes (McNemar's exact test is
  the sign test on the discordant pairs): the exact sign test; its smallest
  one-sided p-value with n runs is 2^-n (1/32 at 5 runs);
* a proportion: the exact binomial test and the Clopper-Pearson interval.

Each function takes arrays whose last axis is the runs, so the calibration
(:mod:`replication.evidence.calibration`) passes thousands of simulated
experiments through the very code that decides, at once.
"""

from dataclasses import dataclass

import numpy as np
from scipy import stats

from replication.evidence.settings import INFERENCE


@dataclass(frozen=True)
class Test:
    """A statistic's estimate with its 90 % interval (each bound one-sided 95 %) and the one-sided p-values
    of its true value lying above (``p_above``) and below (``p_below``) the reference tested.  Arrays over
    the leading axes when the input was a batch; NaN where the data define no test (every run equal)."""

    value: np.ndarray
    low: np.ndarray
    high: np.ndarray
    p_above: np.ndarray
    p_below: np.ndarray
    runs: int
    method: str

    @property
    def defined(self) -> np.ndarray:
        return np.isfinite(self.p_above) & np.isfinite(self.p_below)


def mean_test(values, reference=0.0) -> Test:
    """Student's one-sample t-test of the mean of ``values`` against ``reference`` (paired: the per-run
    differences), with the t interval; undefined (NaN) where every value is the same."""
    x = np.asarray(values, dtype=float)
    n = x.shape[-1]
    mean = x.mean(axis=-1)
    se = x.std(axis=-1, ddof=1) / np.sqrt(n) if n > 1 else np.full(mean.shape, np.nan)
    return t_test(mean, se, n - 1, n, reference)


def t_test(estimate, se, df, runs: int, reference=0.0, method: str = "t", alpha: float | None = None) -> Test:
    """An estimate with standard error ``se`` against ``reference``, its studentised difference referred to
    Student's t with ``df`` degrees of freedom, with the interval of that t whose each bound is one-sided at
    ``alpha`` (None: INFERENCE.alpha); undefined (NaN) where the standard error vanishes or ``df`` < 1."""
    estimate, se = np.asarray(estimate, dtype=float), np.asarray(se, dtype=float)
    spread = se > 1e-12 * np.maximum(1.0, np.abs(estimate))
    if df < 1:
        spread = np.zeros(np.shape(spread), dtype=bool)
    with np.errstate(all="ignore"):
        t = np.where(spread, (estimate - reference) / se, np.nan)
        half = stats.t.ppf(1 - (INFERENCE.alpha if alpha is None else alpha), max(df, 1)) * se
    # each tail directly, never one as 1 minus the other (which rounds a tail under 1e-16 to 0)
    p_above, p_below = stats.t.sf(t, max(df, 1)), stats.t.cdf(t, max(df, 1))
    low, high = np.where(spread, estimate - half, np.nan), np.where(spread, estimate + half, np.nan)
    return Test(estimate, low, high, p_above, p_below, runs, method)


def sign_test(values, reference=0.0) -> Test:
    """The exact sign test of the median of ``values`` against ``reference`` (ties dropped), with the
    distribution-free interval between order statistics; undefined where every value ties the reference."""
    x = np.asarray(values, dtype=float)
    n = x.shape[-1]
    above, below = (x > reference).sum(axis=-1), (x < reference).sum(axis=-1)
    untied = above + below
    p_above = np.where(untied > 0, stats.binom.sf(above - 1, untied, 0.5), np.nan)
    p_below = np.where(untied > 0, stats.binom.sf(below - 1, untied, 0.5), np.nan)
    ordered = np.sort(x, axis=-1)
    rank = int((stats.binom.cdf(np.arange(n + 1), n, 0.5) <= INFERENCE.alpha).sum())  # [x_(rank), x_(n + 1 - rank)]
    if rank >= 1:
        low, high = ordered[..., rank - 1], ordered[..., n - rank]
    else:
        low = high = np.full(x.shape[:-1], np.nan)
    return Test(np.median(x, axis=-1), low, high, p_above, p_below, n, "exact sign test")


def paired_binary_test(differences) -> Test:
    """Paired yes/no outcomes (``differences`` in {-1, 0, 1}: ours minus theirs per run): McNemar's exact
    test, the sign test on the discordant pairs, and a conservative interval for the difference of the
    two rates, p10 - p01, from the Clopper-Pearson bounds of each (each at INFERENCE.alpha / 2)."""
    d = np.asarray(differences, dtype=float)
    n = d.shape[-1]
    found = sign_test(d)
    wins, losses = (d > 0).sum(axis=-1), (d < 0).sum(axis=-1)
    win_low, win_high = clopper_pearson(wins, n, 1 - INFERENCE.alpha)
    loss_low, loss_high = clopper_pearson(losses, n, 1 - INFERENCE.alpha)
    return Test(d.mean(axis=-1), win_low - loss_high, win_high - loss_low, found.p_above, found.p_below, n,
                "exact McNemar (sign) test")


def proportion_test(successes, runs: int, reference: float) -> Test:
    """The exact binomial test of a rate against ``reference``, with the Clopper-Pearson interval."""
    k = np.asarray(successes)
    low, high = clopper_pearson(k, runs, 1 - 2 * INFERENCE.alpha)
    return Test(k / runs, low, high, stats.binom.sf(k - 1, runs, reference), stats.binom.cdf(k, runs, reference),
                runs, "exact binomial test")


def clopper_pearson(successes, runs: int, level: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
    """The exact (Clopper-Pearson) interval of a rate: what ``binomtest(k, n).proportion_ci(method='exact')``
    gives, for arrays of counts at once."""
    k = np.asarray(successes, dtype=float)
    tail = (1 - level) / 2
    low = np.where(k > 0, stats.beta.ppf(tail, np.maximum(k, 1), runs - k + 1), 0.0)
    high = np.where(k < runs, stats.beta.isf(tail, k + 1, np.maximum(runs - k, 1)), 1.0)
    return low, high


def holm(p_values) -> np.ndarray:
    """Holm's step-down adjustment of the p-values along the last axis (NaN: not in the family)."""
    p = np.asarray(p_values, dtype=float)
    family = np.isfinite(p)
    m = family.sum(axis=-1, keepdims=True)
    order = np.argsort(np.where(family, p, np.inf), axis=-1)
    ranked = np.take_along_axis(np.where(family, p, np.inf), order, axis=-1)
    multiplier = np.maximum(m - np.arange(p.shape[-1]), 1)  # past the family: p is inf, replaced below
    adjusted = np.minimum(1.0, np.maximum.accumulate(np.where(np.isfinite(ranked), ranked * multiplier, 1.0),
                                                     axis=-1))
    out = np.empty_like(adjusted)
    np.put_along_axis(out, order, adjusted, axis=-1)
    return np.where(family, out, np.nan)


def detectable(sd: float, runs: int) -> float:
    """The smallest true mean (in the units of ``sd``, the per-run spread) that a one-sided t-test at INFERENCE.alpha
    over ``runs`` runs detects with probability :data:`INFERENCE.power` (the normal-theory approximation)."""
    if runs < 2 or not np.isfinite(sd):
        return float("nan")
    quantiles = stats.t.ppf(1 - INFERENCE.alpha, runs - 1) + stats.t.ppf(INFERENCE.power, runs - 1)
    return float(quantiles * sd / np.sqrt(runs))


def said_p(p: float) -> str:
    """A p-value as a verdict states it."""
    return "p < 1e-4" if p < 1e-4 else f"p = {p:.2g}"
