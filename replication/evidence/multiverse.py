"""A claim across its paper's multiverse: its verdict in every case (a universe of run-level readings, scored
by each of the claim's readings) and whether an open choice moves it (:mod:`replication.evidence.robustness`)."""

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from replication.evidence.checks import Check, Result

from replication.evidence.claims import Claim
from replication.evidence.inference import said_p
from replication.evidence.robustness import DECISIVE, ChoiceEffect, Pairing, adjust, paired_effect
from replication.evidence.schema import RobustnessResult
from replication.evidence.statistics import Estimate
from replication.evidence.verdict import Outcome, Verdict

# how close a verdict is to the claim holding: the best case for the paper has the highest
CLOSENESS = {Outcome.REPRODUCED: 3, Outcome.INCONCLUSIVE: 2, Outcome.NOT_REPRODUCED: 1, Outcome.NOT_TESTABLE: 0}
READING = "reading"  # the scoring readings, a choice of their own beside the run-level ones
BASIS = "compared at"  # what the methods are given in common (Reading.compared_at): equal N, or a budget
SCORING = (READING, BASIS)  # choices made in scoring the runs, not in running them
SHOWN_FLIPS = 4  # in a claim's one-line summary; its page lists every case


def _alternative(choice: str, alternative: str) -> str:
    if choice == READING:
        return f"scored by '{alternative}'"
    return f"compared at {alternative}" if choice == BASIS else f"{choice}={alternative}"


@dataclass(frozen=True)
class Case:
    universe: str
    picks: tuple[tuple[str, str], ...]  # (choice, alternative) of the universe, then BASIS's and READING's
    result: Result

    @property
    def verdict(self) -> Verdict:
        return self.result.verdict

    @property
    def deciding(self) -> Check | None:
        return self.result.deciding

    @property
    def held(self) -> float:
        """The share of its testable checks that hold (a tie-break between cases with one outcome)."""
        testable = [c for c in self.result.checks if c.verdict.outcome is not Outcome.NOT_TESTABLE]
        return sum(c.verdict.outcome is Outcome.REPRODUCED for c in testable) / max(len(testable), 1)

    @property
    def label(self) -> str:
        return f"{self.universe} (scored by: {dict(self.picks)[READING]})"


@dataclass(frozen=True)
class Robustness:
    """One claim's verdicts over its cases: the default (first universe, first reading) and the rest."""

    claim: Claim
    cases: tuple[Case, ...]

    @property
    def default(self) -> Case:
        return self.cases[0]

    @property
    def testable(self) -> list[Case]:
        return [c for c in self.cases if c.verdict.outcome is not Outcome.NOT_TESTABLE]

    @property
    def deciding(self) -> str:
        """The statistic whose movement is tested: the check that decided the default case."""
        return self.default.deciding.what if self.default.deciding else ""

    @cached_property
    def effects(self) -> list[ChoiceEffect]:
        """Each alternative other than the default: its paired effect on the deciding statistic against its
        twin (the case that differs only in that choice, set to its default; where a design has no twins,
        Sobol points, the default case), and how many of its cases' verdicts differ from the twin's.  A
        scoring reading, and a statistic with no per-run values (a published cell, a ranking), count only
        conflicting decisive verdicts (reproduced against not reproduced), and so does a time (a deciding check
        :attr:`~replication.evidence.checks.Check.timed`: load, not the reading, may move it).  A reading at
        equal cost is an alternative of :data:`BASIS` (its twin: the same universe scored by the default
        reading), not of :data:`READING`, whose alternatives are the readings at equal N."""
        testable = self.testable
        timed = self.default.deciding is not None and self.default.deciding.timed
        cases = {c.picks: c for c in testable}
        default_picks = dict(self.default.picks)

        def twin(case: Case, choice: str) -> Case | None:
            swapped = {choice, READING} if choice == BASIS else {choice}  # another basis is another reading
            return cases.get(tuple((ch, default_picks[ch] if ch in swapped else a) for ch, a in case.picks))

        found = []
        for choice, alternative in dict.fromkeys(p for c in testable for p in c.picks):
            if default_picks.get(choice) == alternative:
                continue
            under = [c for c in testable if (choice, alternative) in c.picks]
            if choice == READING:  # a reading at equal cost counts under BASIS
                under = [c for c in under if dict(c.picks).get(BASIS) == default_picks.get(BASIS)]
            if not under:
                continue
            twins = [(c, twin(c, choice)) for c in under]
            pairs = [(c, t) for c, t in twins if t is not None]
            compared = Pairing.TWIN if pairs else Pairing.DEFAULT
            pairs = pairs or [(c, self.default) for c in under]
            unpaired = Pairing.READINGS if choice in SCORING else Pairing.TIMES if timed else None
            effect, p = (None, math.nan) if unpaired else self._paired(pairs)
            if unpaired or effect is None:
                compared = unpaired or Pairing.VERDICTS
                flips = sum({c.verdict.outcome, t.verdict.outcome} == DECISIVE for c, t in pairs)
            else:
                flips = sum(c.verdict.outcome is not t.verdict.outcome for c, t in pairs)
            found.append((choice, alternative, effect, p, flips, len(pairs), compared))
        return adjust(found)

    def _paired(self, pairs: list[tuple[Case, Case]]) -> tuple[Estimate | None, float]:
        """The deciding statistic's paired effect in the first pair that has it per run on both sides."""
        for case, twin in pairs:
            ours, theirs = (_per_run(c, self.deciding) for c in (case, twin))
            if ours and theirs:
                return paired_effect(ours, theirs)
        return None, math.nan

    @property
    def moving(self) -> list[ChoiceEffect]:
        return [e for e in self.effects if e.moves]

    @property
    def robust(self) -> bool | None:
        """No alternative moves the verdict; None when fewer than two cases are testable."""
        return None if len(self.testable) < 2 else not self.moving

    @property
    def flipped_by(self) -> list[str]:
        """The alternatives the verdict depends on, as a reader sees them: 'bests=rescored (+0.3 [0.1, 0.5],
        Holm p = 0.01)', "scored by 'the other rule' (2 of 2 decisive verdicts conflict)"."""
        return [f"{_alternative(e.choice, e.alternative)} ({_effect(e)})" for e in self.moving]

    @property
    def best_case(self) -> Case:
        return max(self.cases, key=lambda c: (CLOSENESS[c.verdict.outcome], c.held))

    @property
    def summary(self) -> str:
        testable = self.testable
        if self.robust is None:
            return f"not testable across readings ({len(testable)} of {len(self.cases)} cases testable)"
        tested = [e for e in self.effects if e.effect is not None]
        if self.robust:
            largest = max((e for e in tested if np.isfinite(e.effect.value)), key=lambda e: abs(e.effect.value),
                          default=None)
            said = (f"; largest effect on {self.deciding}: {_alternative(largest.choice, largest.alternative)} "
                    f"{_effect(largest)}") if largest else ""
            return (f"robust: no open choice moves the verdict ({len(self.effects)} alternatives, "
                    f"{len(testable)} cases){said}")
        flips = self.flipped_by
        flips = "; ".join(flips[:SHOWN_FLIPS]) + (f"; {len(flips) - SHOWN_FLIPS} more" if len(flips) > SHOWN_FLIPS
                                                   else "")
        best = self.best_case
        number = f" ({best.deciding.number})" if best.deciding and best.deciding.number else ""
        return (f"depends on the reading: moved by {flips}; "
                f"best case for the paper: {best.verdict.outcome.value}{number} under {best.label}")

    def as_result(self) -> RobustnessResult:
        """What the scorecard shows of it (``summary.json``'s ``multiverse``)."""
        best = self.best_case
        return RobustnessResult(self.robust, self.summary, self.deciding, len(self.cases), tuple(self.flipped_by),
                                best.label, best.verdict, best.deciding.number if best.deciding else "")


def _per_run(case: Case, what: str) -> dict[int, float]:
    check = next((c for c in case.result.checks if c.what == what), None)
    return {} if check is None else {k: v for k, v in check.per_run.items() if np.isfinite(v)}


def _effect(e: ChoiceEffect) -> str:
    if e.effect is None:
        return f"{e.flips} of {e.compared} decisive verdicts conflict"
    if e.effect.method == "the same runs":
        return "no effect: the same runs"
    return f"{e.effect.value:+.3g} [{e.effect.low:.3g}, {e.effect.high:.3g}], Holm {said_p(e.adjusted)}"
