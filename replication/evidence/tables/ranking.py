"""Methods ranked over sequences (:mod:`replication.evidence.ranking`), and every pair of them."""

import itertools
from dataclasses import dataclass

import pandas as pd

from replication.evidence.ranking import Ranking, rankings, unreliable
from replication.evidence.tables.table import Table, TableKind, TableSpec

@dataclass(frozen=True, kw_only=True)
class Ranked(TableSpec):
    """Methods ranked by mean ``metric`` over the values of ``over`` (the sequences), one ranking per value of
    ``by`` if given (:func:`~replication.evidence.ranking.rankings`)."""

    metric: str
    over: str = "scene"
    by: str | None = None


def _note(found: dict[str, Ranking], experiment: dict) -> str:
    """The lines under a ranking: why it is not reliable (if so), and how its rank sets fare on a sequence
    left out."""
    said = "; ".join(dict.fromkeys(filter(None, (unreliable(r, experiment) for r in found.values()))))
    caveat = f"{said[:1].upper()}{said[1:]}: the probabilities describe these runs and decide no claim. " if said else ""
    return caveat + _held_out(list(found.values()))


def _held_out(found: list[Ranking]) -> str:
    """'Leaving one sequence out, ...': how many orders the other sequences show hold on the one left out
    (summed over the table's rankings of three sequences or more)."""
    found = [r for r in found if len(r.sequences) >= 3]
    if not found:
        return ""
    held, shown = (sum(counts) for counts in zip(*(r.out_of_sample for r in found)))
    sequences = max(len(r.sequences) for r in found)
    if not shown:
        return (f"Leaving one of the {sequences} sequences out, the others show no order between two methods: "
                "the rank sets are as wide as so few sequences leave them.")
    return (f"Leaving one of the {sequences} sequences out, {held} of the {shown} orders the others show between "
            "two methods hold on the sequence left out.")


class RankingTable(TableKind):
    """Methods ranked by their mean ``metric`` over the sequences, best first, with how stable that is
    (:mod:`replication.evidence.ranking`): the mean over the sequences (95% percentile interval of the
    two-level bootstrap), the probability of ranking first, and the mean rank with its 95% interval."""

    kind = "ranking"
    compares = False
    Spec = Ranked

    def build(self, records: pd.DataFrame) -> Table:
        found = rankings(records, self.spec.metric, self.spec.over, self.spec.by)
        rows = [{"condition": group or "-", "method": self.label(method), "sequences": len(ranked.sequences),
                 "runs": ranked.runs, self.spec.metric: ranked.score(i),
                 "P(best)": round(float(ranked.p_best[i]), 3), "rank": ranked.rank(i)}
                for group, ranked in found.items() for i, method in enumerate(ranked.methods)]
        return Table(pd.DataFrame(rows), note=_note(found, self.experiment))


class Pairwise(TableKind):
    """Every pair of ranked methods, the better-ranked first: the probability that A's mean over the
    sequences beats B's (two-level bootstrap), the mean of the paired per-sequence differences A - B
    with its t interval over the sequences, and on how many sequences A is ahead."""

    kind = "pairwise"
    compares = False
    Spec = Ranked

    def build(self, records: pd.DataFrame) -> Table:
        found, metric = rankings(records, self.spec.metric, self.spec.over, self.spec.by), self.spec.metric
        rows = [{"condition": group or "-", "A": self.label(ranked.methods[a]),
                 "B": self.label(ranked.methods[b]), "sequences": len(ranked.sequences), "runs": ranked.runs,
                 "P(A beats B)": round(float(ranked.beats[a, b]), 3),
                 f"{metric} A - B": ranked.difference(a, b), "A ahead on (sequences)": ranked.wins(a, b)}
                for group, ranked in found.items()
                for a, b in itertools.combinations(range(len(ranked.methods)), 2)]
        return Table(pd.DataFrame(rows), note=_note(found, self.experiment))

