"""``best`` and ``rank``: a method's place among others ranked over several sequences
(:mod:`replication.evidence.ranking`)."""

from dataclasses import dataclass

import pandas as pd

from replication.condition import values_of
from replication.evidence.checks import Check, finite
from replication.evidence.comparisons import best_test
from replication.evidence.ranking import rankings, unreliable
from replication.evidence.settings import INFERENCE
from replication.evidence.statistics import Estimate
from replication.evidence.verdict import Outcome, Verdict
from replication.evidence.claim_tests.base import ClaimTest, Measured
from replication.evidence.claim_tests.threshold import threshold_verdict


class Best(ClaimTest):
    """``method`` ranks first in mean ``metric`` over the sequences (the condition variable ``over``,
    default ``scene``; ``group``: one value of the ranking's ``by`` variable): one check per competitor, the
    paired t-test over the sequences of the per-sequence difference of their means
    (:func:`~replication.evidence.comparisons.best_test`).  Reproduced where it beats every competitor at 5 %;
    not reproduced where some competitor is better, after Holm across them.  P(best) and the rank interval of
    the two-level bootstrap (:mod:`replication.evidence.ranking`) are shown beside it and decide nothing.  A
    ranking that is not reliable (too few runs or sequences, sequences cut short) decides nothing."""

    name = "best"

    @dataclass(frozen=True, kw_only=True)
    class Spec(Measured):
        """A method's ranking (:func:`_ranking`): among ``among`` (every method), over the ``sequences``
        (values of ``over``; every one), in the ranking of ``group`` (a value of ``by``)."""

        method: str
        among: list[str] | None = None
        sequences: list[str] | None = None
        over: str = "scene"
        by: str | None = None
        group: str = ""

    def checks(self, records, tables):
        metric, method = self.spec.metric, self.spec.method
        found = _ranking(records, self.spec)
        if found is None:
            return []
        i = found.index(method)
        tested = best_test(found.per_sequence_means, i, found.lower_is_better)
        caveat = unreliable(found, self.experiment)
        rank = found.rank(i)
        description = f"P(best) = {found.p_best[i]:.2f}, rank [{rank.low:.0f}, {rank.high:.0f}] (description only)"
        checks = []
        others = [m for m in found.methods if m != method]
        sign = -1.0 if found.lower_is_better else 1.0
        for j, other in enumerate(others):
            what = f"{method} - {other}, mean {metric} over {len(found.sequences)} sequences x {found.runs} run(s)"
            difference = Estimate(sign * float(tested.gain.value[j]),
                                  *sorted([sign * float(tested.gain.low[j]), sign * float(tested.gain.high[j])]),
                                  len(found.sequences), "sequence-level paired t", 1 - 2 * INFERENCE.alpha)
            if caveat:
                verdict = Verdict(Outcome.NOT_TESTABLE, f"{caveat}; {description}")
            else:
                verdict = threshold_verdict(finite(tested.p_for[j]), finite(tested.p_against[j]),
                                             f"{other} is better", f"; {description}")
            checks.append(Check(what, verdict, difference, reference=0.0))
        return checks


def _ranking(records: pd.DataFrame, spec: "Best.Spec"):
    """The ranking a ``best`` or ``rank`` claim is about (None where its method is not ranked): the runs of its
    ``among`` methods (with ``method``) over its ``sequences`` (values of the variable ``over``), every one where
    unset, in the ranking of its ``group``."""
    keep = pd.Series(True, index=records.index)
    if spec.among:
        keep &= records["method"].isin([spec.method, *spec.among])
    if spec.sequences:
        keep &= values_of(records, spec.over).isin(spec.sequences)
    found = rankings(records[keep], spec.metric, spec.over, spec.by).get(spec.group)
    return found if found is not None and spec.method in found.methods else None


class Rank(ClaimTest):
    """``method`` ranks among the first ``top`` in mean ``metric`` over the sequences (``among``, ``sequences``,
    ``over`` as for ``best``): its 95 % rank set (:func:`~replication.evidence.ranking.rank_set`: the paired
    t-tests over the sequences, Holm across them) within ranks 1 to ``top``: reproduced; wholly below ``top``:
    not reproduced; else inconclusive.  A ranking that is not reliable decides nothing."""

    name = "rank"

    @dataclass(frozen=True, kw_only=True)
    class Spec(Best.Spec):
        top: int

    def checks(self, records, tables):
        method = self.spec.method
        found = _ranking(records, self.spec)
        if found is None:
            return []
        rank, top = found.rank(found.index(method)), self.spec.top
        what = f"{method}'s rank in mean {self.spec.metric} among {len(found.methods)} over {len(found.sequences)} sequences, at most {top}"
        caveat = unreliable(found, self.experiment)
        if caveat:
            verdict = Verdict(Outcome.NOT_TESTABLE, caveat)
        elif rank.high <= top:
            verdict = Verdict(Outcome.REPRODUCED, f"rank set [{rank.low:.0f}, {rank.high:.0f}]")
        elif rank.low > top:
            verdict = Verdict(Outcome.NOT_REPRODUCED, f"rank set [{rank.low:.0f}, {rank.high:.0f}]")
        else:
            verdict = Verdict(Outcome.INCONCLUSIVE, f"rank set [{rank.low:.0f}, {rank.high:.0f}] spans rank {top}")
        return [Check(what, verdict, rank, reference=float(top))]
