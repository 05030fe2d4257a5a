"""A claim's reading decided: the :class:`Check` values its test returns (each a comparison, the number that
decided it and its verdict) combined into the reading's :class:`Result` by
:func:`~replication.evidence.verdict.decide` (Holm across the checks)."""

import math
from dataclasses import dataclass, field, replace

import numpy as np

from replication.evidence.criteria import Replication
from replication.evidence.inference import said_p
from replication.evidence.statistics import Estimate, said_level
from replication.evidence.verdict import OUTCOMES, Outcome, Verdict, decide


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
    replication: Replication | None = None  # the paper's effect and ours, where it quotes a size (criteria.py)

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
        return cls(Verdict(outcome, why, finite(p_for[i]), finite(against)), tuple(checks), deciding)


def _after_holm(check: Check, outcome: Outcome, adjusted: float, family: int) -> Check:
    """The check with the outcome the reading's family gives it (its own test's, unless Holm undoes it)."""
    if outcome is check.verdict.outcome or check.verdict.outcome is Outcome.NOT_TESTABLE:
        return check
    own = check.verdict
    why = f"{own.why}; not significant after Holm across {family} checks ({said_p(adjusted)})" \
        if own.outcome is Outcome.NOT_REPRODUCED else own.why
    return replace(check, verdict=Verdict(outcome, why, own.p_for, own.p_against))


def finite(value) -> float | None:
    """A float, None where it is not finite (a p-value no test gave)."""
    value = float(value)
    return value if math.isfinite(value) else None
