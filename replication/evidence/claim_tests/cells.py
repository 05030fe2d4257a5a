"""``cells``: the published cells a claim owns, as our tables judged them."""

from dataclasses import dataclass


from replication.evidence.checks import Check
from replication.evidence.verdict import Outcome, Verdict
from replication.evidence.claim_tests.base import ClaimSpec, ClaimTest, listed


class Cells(ClaimTest):
    """The published cells this claim owns, as judged in the named tables of ours (``tables:``)."""

    name = "cells"

    @dataclass(frozen=True, kw_only=True)
    class Spec(ClaimSpec):
        tables: str | list[str]

    @property
    def tables(self):
        return listed(self.spec.tables)

    def checks(self, records, tables):
        found = []
        for name in self.tables:
            table = tables.get(name)
            for cell in [] if table is None else table.cells:
                what = f"{cell.method} {cell.experiment} {cell.condition}".strip()
                if cell.rating:  # a rating: the proportion of runs behind it is the number
                    what = f"{what} (ours: {cell.rating})"
                found.append(Check(what, cell.verdict or Verdict(Outcome.NOT_TESTABLE), cell.estimate,
                                   reference=cell.paper_number, paper=cell.paper_number))
        return found
