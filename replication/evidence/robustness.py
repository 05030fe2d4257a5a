"""Whether a verdict depends on a reading: the paired effect of each open choice on the deciding statistic.

Universes of a paper's multiverse share their data by construction (a run's
seed is its method, condition and repetition, whichever reading is set), so a
choice's effect on the number that decided a claim is a paired difference
over repetitions: the statistic under the alternative minus the same
statistic in its twin universe (the same universe with that choice at its
default).  A verdict *depends on the reading* only where a choice's effect is
significant after Holm's correction across the claim's choices (two-sided
t-test at 5 %) and its universe's verdict differs from the twin's; a verdict
that merely reads differently in a universe of 5 runs, with no effect to
show for it, is noise and leaves the claim *robust*.

A scoring reading (another definition of the claim's test on the same runs)
has no common statistic to pair: the claim depends on it only where the two
give conflicting decisive verdicts (reproduced under one, not reproduced under
the other), each of which holds its own error rate.  So does a time (a time per
frame, frames per second): each universe's runs were timed when they ran, so a
difference between universes mixes the reading with the machine's load at the
two moments, and no paired effect of the reading can be read from it.
"""

import math
from dataclasses import dataclass
from enum import Enum

import numpy as np

from replication.evidence.inference import holm, mean_test
from replication.evidence.statistics import Estimate, paired_difference
from replication.evidence.verdict import Outcome
from replication.evidence.settings import INFERENCE

DECISIVE = {Outcome.REPRODUCED, Outcome.NOT_REPRODUCED}  # two decisive verdicts conflict; one inconclusive does not


class Pairing(Enum):
    """What an alternative's cases are compared with."""

    TWIN = "twin"  # the same universe with the choice at its default: a paired effect
    DEFAULT = "default"  # a design without twins (Sobol points): the default case, the difference confounded
    READINGS = "readings"  # another scoring reading of the same runs: no common statistic to pair
    TIMES = "times"  # a time measured as each universe ran: a difference mixes the reading with the machine's load
    VERDICTS = "verdicts"  # a statistic with no per-run values (a published cell, a ranking): verdicts alone

    @property
    def unpaired(self) -> bool:
        """Only conflicting decisive verdicts count (no effect is estimated)."""
        return self in UNPAIRED

    @property
    def said(self) -> str:
        """Why no effect is shown, for a reader ("" where one is)."""
        return UNPAIRED.get(self, "")


UNPAIRED = {Pairing.READINGS: "another scoring reading", Pairing.TIMES: "a time: load, not the reading, may move it",
            Pairing.VERDICTS: "no per-run statistic"}


@dataclass(frozen=True)
class ChoiceEffect:
    """One alternative's paired effect on the deciding statistic, and whether it moves the verdict."""

    choice: str
    alternative: str
    effect: Estimate | None  # mean (alternative - twin) over shared repetitions, 95 % t interval
    p: float  # two-sided, before Holm (NaN: nothing to pair)
    adjusted: float  # Holm across the claim's alternatives
    flips: int  # cases whose verdict differs from the twin's
    compared: int  # cases compared
    paired: Pairing

    @property
    def significant(self) -> bool:
        return math.isfinite(self.adjusted) and self.adjusted < INFERENCE.alpha

    @property
    def moves(self) -> bool:
        """Whether the verdict depends on this alternative."""
        return bool(depends(self.adjusted, self.flips > 0)) or (self.paired.unpaired and self.flips > 0)


def paired_effect(alternative: dict, twin: dict) -> tuple[Estimate | None, float]:
    """The mean of ``alternative - twin`` over the repetitions both have (per-run values keyed by
    repetition), its 95 % t interval, and the two-sided p-value of no effect (NaN: fewer than 2 shared
    repetitions or every difference equal but not zero; runs the choice leaves untouched: exactly 0)."""
    shared = sorted(set(alternative) & set(twin))
    if len(shared) < 2:
        return None, math.nan
    ours, theirs = (np.array([side[r] for r in shared], dtype=float) for side in (alternative, twin))
    if np.array_equal(ours, theirs):  # the choice leaves these runs as they are: no effect, exactly
        return Estimate(0.0, 0.0, 0.0, len(shared), "the same runs"), 1.0
    tested = mean_test(ours - theirs)
    p = float(min(1.0, 2 * min(tested.p_above, tested.p_below)))
    return paired_difference(ours, theirs), p


def depends(adjusted, flipped) -> np.ndarray:
    """The rule: an alternative moves the verdict where its verdict differs from its twin's and its effect on
    the deciding statistic survives Holm (``adjusted``) at 5 %."""
    return np.asarray(flipped) & (np.nan_to_num(np.asarray(adjusted, dtype=float), nan=1.0) < INFERENCE.alpha)


def adjust(effects: list[tuple[str, str, Estimate | None, float, int, int, Pairing]]) -> list[ChoiceEffect]:
    """The alternatives' effects with Holm's correction across them (unpaired rows take no part)."""
    p = np.array([math.nan if e[6].unpaired else e[3] for e in effects], dtype=float)
    adjusted = holm(p) if len(p) else p
    return [ChoiceEffect(*e[:4], float(a), *e[4:]) for e, a in zip(effects, adjusted)]
