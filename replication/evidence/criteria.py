"""Did the paper's effect replicate?  The criteria the large replication projects judge by, side by side.

No single criterion of replication success is agreed on, so the large projects report several at once: the
Open Science Collaboration (Science 2015), the Reproducibility Project: Cancer Biology (Errington et al.,
eLife 2021, Table 1), Patil, Peng & Leek (Perspectives on Psychological Science 2016), Held (JRSS A 2020),
Held, Micheloud & Pawel (Annals of Applied Statistics 2022) and Simonsohn (Psychological Science 2015).
Each criterion here is a small function of one :class:`Replication`: the original's effect and ours on one
scale, oriented so that a positive effect favours the claim, each with its standard error.  They are shown
beside the verdict, never combined into it: the verdict stays the calibrated rule's
(:mod:`replication.evidence.verdict`).

Where the papers print no spread, the original's standard error is ours carried to the paper's run count by
the declared rule (:mod:`replication.evidence.original`): where the paper states no count its runs are taken
as ours, so its variance ratio c = se_o^2 / se_r^2 is n_ours / n_paper times var(A) + var(B) over the paired
variance of the gain, by construction, and never an observation.  Intervals use Student's t with our
n - 1 degrees of freedom (both standard errors come from our runs); the sceptical p-value uses the normal, as
its definition does.  Every function takes arrays, so the calibration runs the same code on thousands of
simulated experiments.
"""

import math
from collections.abc import Callable
from dataclasses import dataclass, fields, replace
from functools import cached_property

import numpy as np
from scipy import stats

LEVEL = 0.95  # the intervals' two-sided coverage, as the projects used
GOLDEN = (1 + math.sqrt(5)) / 2  # Held, Micheloud & Pawel (2022): the golden ratio recalibrates p_S
SCEPTICAL_LEVEL = 0.025  # one-sided: the threshold Held, Micheloud & Pawel (2022) put the golden p_S to
TELESCOPE_POWER = 1 / 3  # Simonsohn (2015): the effect the original had 33 % power to detect


@dataclass(frozen=True)
class Replication:
    """An original effect and ours, on one ``scale`` (a difference, a log ratio, a difference of rates), both
    oriented so that a positive effect favours the claim, with their standard errors; ``p_direction`` is our
    one-sided p-value of no effect (the verdict's direction test: Student's paired t, McNemar's exact test);
    ``spread`` is the per-run standard deviation the picture standardises by; ``runs`` ours, ``paper_runs``
    behind the original (``stated``: by the paper, else by the declared rule)."""

    scale: str
    original: float
    original_se: float
    replication: float
    replication_se: float
    p_direction: float
    runs: int
    paper_runs: float
    stated: bool
    spread: float

    @property
    def c(self):
        """The variance ratio c = se_o^2 / se_r^2 (Held 2020; n_r / n_o for equal per-run spreads)."""
        return self.original_se ** 2 / self.replication_se ** 2

    @property
    def quantile(self):
        """Student's t quantile of the two-sided :data:`LEVEL` interval with n_ours - 1 degrees of freedom."""
        return stats.t.ppf(0.5 + LEVEL / 2, np.asarray(self.runs) - 1)

    def single(self) -> "Replication":
        """The same with plain floats (one check's, as stored)."""
        return replace(self, **{f.name: float(getattr(self, f.name)) for f in fields(self)
                                if f.name not in ("scale", "stated", "runs")}, runs=int(self.runs))


def significant(r: Replication, two_sided: bool = True):
    """Our effect in the original's direction and significant: p_direction < 0.025 (two-sided 5 %, as the
    OSC and the RPCB counted it) or < 0.05 (one-sided 5 %, as the verdicts)."""
    return np.asarray(r.p_direction) < (1 - LEVEL) / (2 if two_sided else 1)


def prediction_interval(r: Replication):
    """Patil, Peng & Leek (2016): where the replication's estimate falls with 95 % probability given the
    original's, theta_o +- q sqrt(se_o^2 + se_r^2) (q the normal quantile there; here Student's t, our
    variances being estimated)."""
    half = r.quantile * np.sqrt(np.square(r.original_se) + np.square(r.replication_se))
    return r.original - half, r.original + half


def relative_effect(r: Replication):
    """Held, Micheloud & Pawel (2022): the relative effect size d = theta_r / theta_o, with Fieller's 95 %
    interval for a ratio of independent estimates, the d with (theta_r - d theta_o)^2 <= q^2 (se_r^2 +
    d^2 se_o^2); unbounded (NaN ends) where the original is not significant at that level."""
    q2 = np.square(r.quantile)
    a = np.square(r.original) - q2 * np.square(r.original_se)
    b = np.asarray(r.replication) * r.original
    c = np.square(r.replication) - q2 * np.square(r.replication_se)
    with np.errstate(all="ignore"):
        root = np.sqrt(b ** 2 - a * c)
        bounded = (a > 0) & (b ** 2 - a * c >= 0)
        low, high = np.where(bounded, (b - root) / a, np.nan), np.where(bounded, (b + root) / a, np.nan)
        return np.asarray(r.replication) / r.original, low, high


def sceptical_p(r: Replication):
    """Held (2020), recalibrated at the golden level (Held, Micheloud & Pawel 2022): the one-sided sceptical
    p-value.  With z_o, z_r the two z-values, z_H^2 = 2 / (1/z_o^2 + 1/z_r^2), z_A^2 = (z_o^2 + z_r^2) / 2
    and c = se_o^2 / se_r^2: z_S^2 = z_H^2 / 2 at c = 1, else (sqrt(z_A^2 (z_A^2 + (c - 1) z_H^2)) - z_A^2) /
    (c - 1); golden: p_S = 1 - Phi(sqrt(phi) z_S) where the two agree in sign, else Phi(sqrt(phi) z_S)."""
    return _sceptical(r.original / np.asarray(r.original_se), r.replication / np.asarray(r.replication_se), r.c,
                      GOLDEN)


def _sceptical(zo, zr, c, recalibration: float = 1.0):
    """The one-sided sceptical p-value of z-values ``zo``, ``zr`` at variance ratio ``c`` (``recalibration``:
    1 nominal, as in Held 2020; :data:`GOLDEN`)."""
    zo2, zr2, c = np.square(zo), np.square(zr), np.asarray(c, dtype=float)
    with np.errstate(all="ignore"):
        harmonic, arithmetic = 2 / (1 / zo2 + 1 / zr2), (zo2 + zr2) / 2
        at_one = np.isclose(c, 1.0)
        z2 = np.where(at_one, harmonic / 2, (np.sqrt(arithmetic * (arithmetic + (c - 1) * harmonic)) - arithmetic)
                      / np.where(at_one, 1.0, c - 1))
    tail = stats.norm.sf(np.sqrt(z2 * recalibration))
    return np.where(np.sign(zo) == np.sign(zr), tail, 1 - tail)


def small_telescope(r: Replication):
    """Simonsohn (2015): d33 = se_o (z_0.975 - z_(1 - 1/3)), the effect the original had 33 % power to detect at
    two-sided 5 %, and our one-sided 95 % upper bound; the replication rules d33 out where the bound is below
    it (an informative failure)."""
    d33 = np.asarray(r.original_se) * (stats.norm.ppf(0.975) + stats.norm.ppf(TELESCOPE_POWER))
    upper = r.replication + stats.t.ppf(0.95, np.asarray(r.runs) - 1) * np.asarray(r.replication_se)
    return d33, upper


def fixed_effect(r: Replication):
    """The fixed-effect meta-analysis of the two (inverse-variance weights), its estimate, standard error and
    two-sided p-value (normal)."""
    wo, wr = 1 / np.square(r.original_se), 1 / np.square(r.replication_se)
    estimate = (wo * r.original + wr * np.asarray(r.replication)) / (wo + wr)
    se = 1 / np.sqrt(wo + wr)
    return estimate, se, 2 * stats.norm.sf(np.abs(estimate / se))


def _inside(value, low, high):
    return (np.asarray(low) <= value) & (value <= np.asarray(high))


def _original_in_ours(r: Replication):
    half = r.quantile * np.asarray(r.replication_se)
    return _inside(r.original, r.replication - half, r.replication + half)


def _ours_in_original(r: Replication):
    half = r.quantile * np.asarray(r.original_se)
    return _inside(r.replication, r.original - half, r.original + half)


def _telescope_open(r: Replication):
    d33, upper = small_telescope(r)
    return upper >= d33


def _meta(r: Replication):
    estimate, _, p = fixed_effect(r)
    return (estimate > 0) & (p < 1 - LEVEL)


@dataclass(frozen=True)
class Criterion:
    """One criterion of replication success: its column, its words, where it comes from, whether it is a
    test at 5 % by design (the others describe and hold no error rate), and whether an effect meets it."""

    key: str
    name: str
    source: str
    test: bool
    met: Callable[[Replication], np.ndarray]


RPCB_FIVE = ("significant", "original_in_ours", "ours_in_original", "prediction", "meta")  # its composite's five


def _composite(r: Replication):
    """Errington et al. (2021): at least 3 of the 5 binary criteria (RPCB_FIVE) met."""
    return sum(np.asarray(CRITERION[key].met(r), dtype=int) for key in RPCB_FIVE) >= 3


CRITERIA = (
    Criterion("direction", "same direction", "OSC 2015; RPCB 2021", False,
              lambda r: np.asarray(r.replication) > 0),
    Criterion("significant", "same direction and significant (two-sided 5 %)", "OSC 2015; RPCB 2021", True,
              significant),
    Criterion("significant_one_sided", "same direction and significant (one-sided 5 %, as the verdicts)",
              "this project's rule", True, lambda r: significant(r, two_sided=False)),
    Criterion("original_in_ours", "original inside our 95 % interval", "OSC 2015; RPCB 2021", False,
              _original_in_ours),
    Criterion("ours_in_original", "ours inside the original's 95 % interval", "RPCB 2021", False,
              _ours_in_original),
    Criterion("prediction", "ours inside the 95 % prediction interval", "Patil, Peng & Leek 2016; RPCB 2021",
              False, lambda r: _inside(r.replication, *prediction_interval(r))),
    Criterion("at_least_as_large", "ours at least as large as the original (d >= 1)", "RPCB 2021", False,
              lambda r: relative_effect(r)[0] >= 1),
    Criterion("sceptical", f"sceptical p-value, golden, <= {SCEPTICAL_LEVEL}", "Held 2020; Held, Micheloud & "
              "Pawel 2022", False, lambda r: sceptical_p(r) <= SCEPTICAL_LEVEL),
    Criterion("telescope", "d33 not ruled out (small telescopes)", "Simonsohn 2015", False,
              _telescope_open),
    Criterion("meta", "fixed-effect meta-analysis significant (two-sided 5 %), same direction",
              "OSC 2015; RPCB 2021", True, _meta),
    Criterion("composite", "3 of RPCB's 5 (significant, both intervals, prediction, meta)", "RPCB 2021", False,
              _composite),
)
CRITERION = {criterion.key: criterion for criterion in CRITERIA}


@dataclass(frozen=True)
class Assessed:
    """One claim under every criterion: its ``effects`` (its first reading's sized checks, each a paper's
    effect and ours) and how many meet each criterion; where none applies, why (``why_not``)."""

    effects: tuple[Replication, ...] = ()
    why_not: str = ""

    @cached_property
    def _met(self) -> dict[str, int]:
        return {c.key: sum(bool(c.met(r)) for r in self.effects) for c in CRITERIA}

    def met(self, key: str) -> int:
        """How many of the claim's effects meet criterion ``key``."""
        return self._met[key]

    def holds(self, key: str) -> bool | None:
        """Whether every effect of the claim meets criterion ``key`` (None: not applicable)."""
        return self.met(key) == len(self.effects) if self.effects else None

    @property
    def relative(self) -> float:
        """The claim's relative effect size: the median of its effects' d = theta_r / theta_o."""
        return float(np.median([relative_effect(r)[0] for r in self.effects])) if self.effects else math.nan

    @property
    def runs_rule(self) -> str:
        """How the runs behind the paper's numbers were counted: stated by the paper, or the declared rule."""
        stated = {r.stated for r in self.effects}
        return {frozenset({True}): "stated", frozenset({False}): "not stated: the declared rule"}.get(
            frozenset(stated), "some stated, some by the declared rule") if stated else ""


def assess(checks, sized: bool) -> Assessed:
    """A claim's reading's ``checks`` under the criteria (``sized``: its test quotes the paper's size).  A
    size from times measured on another machine is left out, as the verdicts leave out such times
    (``docs/statistics.md``, "Times")."""
    if not sized:
        return Assessed(why_not="not applicable: the claim quotes no size")
    effects = tuple(c.replication for c in checks if c.replication is not None and not c.timed)
    if effects:
        return Assessed(effects)
    if any(c.replication is not None for c in checks):
        return Assessed(why_not="not applicable: its size is a ratio of times measured on the paper's machine")
    return Assessed(why_not="not applicable: no check of its size was testable here")


@dataclass(frozen=True)
class Share:
    """How many of the claims a criterion applies to meet it (``met`` of ``of``), and of their sized effects."""

    met: int
    of: int
    effects_met: int
    effects: int

    @property
    def claims_said(self) -> str:
        return f"{self.met} of {self.of} claims ({100 * self.met / self.of:.0f} %)"

    @property
    def effects_said(self) -> str:
        return f"{self.effects_met} of {self.effects} effects"

    def __str__(self) -> str:
        """'1 of 5 claims (20 %); 7 of 38 effects', or '-' where the criterion applies to no claim."""
        return f"{self.claims_said}; {self.effects_said}" if self.of else "-"


def shares(assessed: dict[str, list[Assessed]]) -> list[dict]:
    """Per paper and over all (``assessed``: each paper's claims), how many meet each criterion of those it
    applies to, as the OSC and RPCB tables count them, by claim and by effect: {"paper", "claims", key:
    :class:`Share`}."""
    rows = []
    for paper, claims in [*assessed.items(), ("all", [a for claims in assessed.values() for a in claims])]:
        applicable = [a for a in claims if a.effects]
        effects = sum(len(a.effects) for a in applicable)
        rows.append({"paper": paper, "claims": len(claims),
                     **{c.key: Share(sum(bool(a.holds(c.key)) for a in applicable), len(applicable),
                                     sum(a.met(c.key) for a in applicable), effects) for c in CRITERIA}})
    return rows


def surviving(assessed: list[Assessed], resamples: int, seed: int) -> tuple[float, float, float, int]:
    """How much of the papers' effects survives: the median over claims of each claim's relative effect size,
    with its 95 % bootstrap interval (percentile; scipy.stats.bootstrap), and the claims behind it."""
    d = np.array([a.relative for a in assessed if a.effects])
    d = d[np.isfinite(d)]
    if len(d) < 2:
        return (float(np.median(d)) if len(d) else math.nan), math.nan, math.nan, len(d)
    found = stats.bootstrap((d,), np.median, confidence_level=LEVEL, n_resamples=resamples, method="percentile",
                            random_state=np.random.default_rng(seed))
    return float(np.median(d)), float(found.confidence_interval.low), float(found.confidence_interval.high), len(d)
