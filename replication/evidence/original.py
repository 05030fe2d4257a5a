"""How many runs stand behind a paper's number: the one declared rule (``docs/statistics.md``).

A paper's mean is itself an estimate, its noise set by the runs it averages.
The rule:

* where the paper states its run count, that count (a table spec's
  ``paper_runs:``, with a comment quoting where the paper says it; a user's
  ``size: {quoted: ..., runs: n}``);
* where it does not, and its numbers are rates of runs (a share of runs that
  succeeded), the fewest runs that can give every one of them at the precision
  printed (95 % and 55 % can only come from a multiple of 20 runs: 20);
* else as many runs as ours (c = n_ours / n_paper = 1).

The papers give no spread: the noise of a paper's number is taken from our
per-run spread at its run count (:mod:`replication.evidence.comparisons`).
The assumption is said beside every verdict that uses it (:attr:`PaperRuns.why`).
"""

import math
from collections.abc import Sequence
from dataclasses import dataclass
from decimal import Decimal

from replication.evidence.quantities import quantity

FEWEST_LIMIT = 1000  # rates no run count up to this gives are read as not rates of runs


@dataclass(frozen=True)
class PaperRuns:
    """The runs behind each of a paper's numbers, whether the paper states them, and the rule's words."""

    n: int | float  # math.inf: the number taken as exact (the rule before, kept as the calibration's control)
    stated: bool
    why: str

    def __str__(self) -> str:
        return self.why


def paper_runs(ours: int, stated: int | None = None, rates: Sequence[str] = (), high: float = 100.0) -> PaperRuns:
    """The rule: ``stated`` where the paper states a count; else the fewest runs that give every printed rate
    in ``rates`` (the paper's numbers as printed, on a scale whose whole is ``high``: 100 for a percentage);
    else ``ours``."""
    if stated:
        return PaperRuns(int(stated), True, f"{int(stated)} runs, stated")
    fewest = fewest_runs(rates, high) if rates else None
    if fewest:
        return PaperRuns(fewest, False, f"{fewest} runs, not stated: the fewest that give {' and '.join(rates)}")
    return PaperRuns(int(ours), False, f"runs not stated: taken as ours, {int(ours)}")


def runs_behind(ours: int, stated: int | None, printed: Sequence[str], metric: str, scale: float = 1.0) -> PaperRuns:
    """The rule for a paper's numbers ``printed`` of ``metric`` in units ``scale`` (a share in %: 100), read as
    rates of runs where the metric is a per-run yes/no outcome."""
    kind = quantity(metric)
    return paper_runs(ours, stated, printed if kind.proportion else (), kind.high * scale)


def fewest_runs(rates: Sequence[str], high: float = 100.0, limit: int = FEWEST_LIMIT) -> int | None:
    """The fewest runs n for which each printed rate (a string, its decimals its precision) is some k / n of
    ``high`` rounded to that precision (None where no n up to ``limit`` gives them all)."""
    printed = [(float(r), 0.5 * 10.0 ** Decimal(r).as_tuple().exponent) for r in rates]
    for n in range(1, limit + 1):
        if all(_gives(value, half, n, high) for value, half in printed):
            return n
    return None


def _gives(value: float, half: float, n: int, high: float) -> bool:
    """Whether some k of n runs, as a share of ``high``, rounds to ``value`` (within ``half`` a last digit)."""
    k = math.floor(value / high * n)
    return any(0 <= j <= n and abs(j / n * high - value) <= half + 1e-9 for j in (k, k + 1))
