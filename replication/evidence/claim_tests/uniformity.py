"""``uniformity``: one point set more uniform than another (no runs)."""

from dataclasses import dataclass


from replication.evidence.checks import Check
from replication.evidence.verdict import Outcome, Verdict
from replication.qmc import discrepancy_table
from replication.evidence.claim_tests.base import ClaimSpec, ClaimTest, listed


class Uniformity(ClaimTest):
    """A point set is more uniform than another: lower discrepancy (``method``, e.g. CD) of ``n`` points in
    each of ``dims`` dimensions.  Deterministic point sets: no runs, no interval."""

    name = "uniformity"
    needs_runs = False

    @dataclass(frozen=True, kw_only=True)
    class Spec(ClaimSpec):
        set: str
        than: str
        dims: int | list[int]
        n: int = 400
        method: str = "CD"

    def checks(self, records, tables):
        spec = self.spec
        table = discrepancy_table(n=spec.n, dims=tuple(listed(spec.dims)), method=spec.method)
        found = []
        for _, row in table.iterrows():
            ours, other = row[spec.set], row[spec.than]
            outcome = Outcome.REPRODUCED if ours < other else Outcome.NOT_REPRODUCED
            found.append(Check(f"{spec.set} vs {spec.than}, s = {int(row['s'])}",
                               Verdict(outcome, f"{ours:.2e} vs {other:.2e}")))
        return found
