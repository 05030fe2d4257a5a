"""The scorecard: each paper's claims with their verdicts, from the results the experiment reports stored.

Each experiment's ``summary.json`` holds, under ``claims``, the result of
every reading that names it (:func:`replication.evidence.claims.evaluate`).
Here they are gathered per claim: the primary reading's verdict, the number
that decided it with its interval, one line of why, and whether the verdict
survives the other readings.  ``reports/claims.csv`` is the same, one row
per claim.
"""

from collections import Counter
from dataclasses import dataclass
from functools import cached_property

import pandas as pd

from replication.evidence.robustness import DECISIVE
from replication.evidence.verdict import BAYES_FLOOR, Outcome, Verdict
from replication.evidence.checks import Check
from replication.evidence.criteria import CRITERIA, Assessed, assess, relative_effect, sceptical_p, shares, surviving
from replication.evidence.settings import INFERENCE
from replication.evidence.claims import Claim, Paper, Reading, load_papers
from replication.evidence.published import load_published, published_path
from replication.evidence.schema import RobustnessResult, Summary
from replication.evidence.summary import experiment_configs, load_summaries, summary_table


@dataclass(frozen=True)
class ReadingResult:
    reading: Reading
    verdict: Verdict
    deciding: Check | None
    checks: tuple[Check, ...]
    scale: str


@dataclass(frozen=True)
class ClaimRow:
    claim: Claim
    results: tuple[ReadingResult, ...]
    multiverse: RobustnessResult | None = None  # its robustness across the paper's multiverse (if it was run)
    multiverse_experiment: str = ""

    @property
    def primary(self) -> ReadingResult:
        return self.results[0]

    @property
    def verdict(self) -> Verdict:
        return self.primary.verdict

    @cached_property
    def assessed(self) -> Assessed:
        """The claim under the replication literature's criteria (:mod:`replication.evidence.criteria`): its
        first reading's sized checks, the paper's effect and ours in each."""
        if self.verdict.outcome is Outcome.NOT_TESTABLE and not self.primary.checks:
            return Assessed(why_not="not applicable: not testable here")
        return assess(self.primary.checks, self.primary.reading.test.sized)

    @property
    def at_equal_cost(self) -> list[ReadingResult]:
        """Its readings with the methods given the same budget (not the paper's reading), beside the primary."""
        return [r for r in self.results if r.reading.basis]

    @property
    def evidence(self) -> list[tuple[str, str]]:
        """The experiments its readings were tested on, each once, with the scale their runs are at."""
        return list(dict.fromkeys((r.reading.experiment, r.scale) for r in self.results if r.scale))

    @property
    def robust(self) -> bool | None:
        """The same verdict in every case of the paper's multiverse (None: not run, or too few cases)."""
        return None if self.multiverse is None else self.multiverse.robust

    @property
    def robustness(self) -> str:
        """Whether the verdict is the same under every reading, or which reading it hinges on: across the
        paper's multiverse of run-level and scoring readings where it was run, else across the scoring
        readings of the stored results (where it hinges only on readings that give conflicting decisive
        verdicts)."""
        if self.multiverse is not None:
            return self.multiverse.summary
        judged = [r for r in self.results if r.verdict.outcome is not Outcome.NOT_TESTABLE]
        if len(self.results) == 1:
            return "one reading"
        if len(judged) < 2:
            return "other readings not testable"
        outcomes = {r.verdict.outcome for r in judged}
        if len(outcomes) == 1:
            return f"the same under all {len(judged)} readings"
        listed = "; ".join(f"{r.verdict.outcome.value} under {r.reading.name}{' (ours)' if r.reading.ours else ''}"
                           for r in judged)
        if DECISIVE <= outcomes:  # each decisive verdict holds its error rate: a real conflict
            return f"hinges on the reading: {listed}"
        return f"no reading contradicts another (an inconclusive reading is no contradiction): {listed}"


def claim_rows(papers: list[Paper], summaries: dict[str, Summary]) -> dict[str, list[ClaimRow]]:
    """Per paper, its claims with every reading's stored result (not testable where none is stored), and
    its robustness across the paper's multiverse where one was run."""
    across = {claim: (name, stored) for name, summary in summaries.items()
              for claim, stored in summary.multiverse.items()}
    return {paper.key: [ClaimRow(claim, tuple(_result(claim, r, summaries) for r in claim.readings) or _untested(claim),
                                 *reversed(across.get(claim.id, ("", None))))
                        for claim in paper.claims] for paper in papers}


def _untested(claim: Claim) -> tuple[ReadingResult]:
    """A claim no reading tests here: not testable, for the reason its entry states."""
    return (ReadingResult(Reading("none here", "", {}), Verdict(Outcome.NOT_TESTABLE, claim.untestable), None, (), ""),)


def _result(claim: Claim, reading: Reading, summaries: dict[str, Summary]) -> ReadingResult:
    summary = summaries.get(reading.experiment)
    if summary is None:
        return ReadingResult(reading, Verdict(Outcome.NOT_TESTABLE, f"not run yet: experiment={reading.experiment}"),
                             None, (), "")
    stored = summary.claims.get(claim.id, {}).get(reading.name)
    if stored is None:
        why = f"no result stored: python -m replication.report experiment={reading.experiment}"
        return ReadingResult(reading, Verdict(Outcome.NOT_TESTABLE, why), None, (), summary.scale)
    return ReadingResult(reading, stored.verdict, stored.deciding, stored.checks, summary.scale)


def tally(rows: list[ClaimRow]) -> dict[str, int]:
    """How many claims have each outcome, in the outcomes' order."""
    counted = Counter(row.verdict.outcome for row in rows)
    return {outcome.value: counted[outcome] for outcome in Outcome if counted[outcome]}


def owner_of_cells(papers: list[Paper], published: pd.DataFrame) -> list[str]:
    """For each published cell (the csv's order), the id of the claim it belongs to ('' if none)."""
    claims = [claim for paper in papers for claim in paper.claims]
    return [next((c.id for c in claims if c.owns(cell)), "") for _, cell in published.iterrows()]


def cell_tallies(cells: pd.DataFrame) -> dict[str, str]:
    """Per claim, what became of the published cells it owns: '12 cells: 3 reproduced, 9 not reproduced
    (8 below the Bayes floor); 2 not compared' (``cells``: the summary of every cell, with its claim)."""
    tallies = {}
    for claim, owned in cells[cells["claim"] != ""].groupby("claim", sort=False):
        compared = owned[owned["outcome"] != ""]
        parts = [f"{n} {outcome}" for outcome, n in compared["outcome"].value_counts().items()]
        floor = int((compared["tag"] == BAYES_FLOOR).sum()) if "tag" in compared else 0
        if floor:
            parts.append(f"{floor} below the Bayes floor")
        if len(owned) > len(compared):
            parts.append(f"{len(owned) - len(compared)} not compared")
        tallies[claim] = f"{len(owned)} cells: " + ", ".join(parts)
    return tallies


def claims_frame(rows: dict[str, list[ClaimRow]], cells: pd.DataFrame, tallies: dict[str, str]) -> pd.DataFrame:
    """``reports/claims.csv``: one row per claim with its verdict, deciding number, interval and its level, runs,
    why, robustness across readings, and the published cells it owns (``cells``: the summary of every
    cell, with its claim)."""
    owned = cells["claim"].value_counts()
    table = []
    for paper, claims in rows.items():
        for row in claims:
            deciding = row.primary.deciding
            estimate = deciding.estimate if deciding and deciding.estimate else None
            table.append({
                "paper": paper, "claim_id": row.claim.id, "claim": row.claim.text, "where": row.claim.where,
                "quote": row.claim.quote.text, "quote_english": row.claim.quote.english,
                "verdict": row.verdict.outcome.value, "reason": row.verdict.why,
                "number": estimate.value if estimate else None, "ci_low": estimate.low if estimate else None,
                "ci_high": estimate.high if estimate else None,
                "level": estimate.level if estimate and estimate.defined else None,  # the interval's coverage
                "runs": estimate.runs if estimate else None,
                "deciding": deciding.shown if deciding else "",
                "at_equal_cost": "; ".join(f"{r.verdict.outcome.value} at {r.reading.compared_at}"
                                           for r in row.at_equal_cost),
                "reading": row.primary.reading.name, "readings": len(row.results), "robustness": row.robustness,
                "robust": row.robust, **_across(row),
                "scale": row.primary.scale,
                "cells": int(owned.get(row.claim.id, 0)),
                "cell_verdicts": tallies.get(row.claim.id, ""), "note": row.claim.note, **_criteria(row.assessed),
            })
    return pd.DataFrame(table)


def _criteria(assessed: Assessed) -> dict:
    """The criteria's columns of ``claims.csv``: per criterion how many of the claim's sized effects meet it
    ("2/3"), the claim's relative effect size, the largest sceptical p-value, how the paper's runs were
    counted, or why none applies."""
    n = len(assessed.effects)
    return {"effects": n, **{f"criterion_{c.key}": f"{assessed.met(c.key)}/{n}" if n else "" for c in CRITERIA},
            "relative_effect": assessed.relative if n else None,
            "sceptical_p": max(float(sceptical_p(r)) for r in assessed.effects) if n else None,
            "paper_runs": assessed.runs_rule, "criteria_not_applicable": assessed.why_not}


def effect_points(rows: dict[str, list[ClaimRow]]) -> pd.DataFrame:
    """Every sized effect of every claim, the paper's and ours standardised by our per-run standard deviation
    (one unit on both axes), each with its 95 % interval's half-width, and its relative effect size."""
    points = []
    for paper, claims in rows.items():
        for row in claims:
            for r in row.assessed.effects:
                d = relative_effect(r)
                points.append({"paper": paper, "claim_id": row.claim.id, "scale": r.scale,
                               "original": r.original / r.spread, "replication": r.replication / r.spread,
                               "original_half": float(r.quantile * r.original_se / r.spread),
                               "replication_half": float(r.quantile * r.replication_se / r.spread),
                               "relative_effect": float(d[0]), "relative_low": float(d[1]),
                               "relative_high": float(d[2])})
    return pd.DataFrame(points, columns=["paper", "claim_id", "scale", "original", "replication", "original_half",
                                         "replication_half", "relative_effect", "relative_low", "relative_high"])


def _across(row: ClaimRow) -> dict:
    """The multiverse's columns of ``claims.csv``: cases, the alternatives that flip the verdict, the
    best case for the paper and its number (empty where the paper's multiverse was not run)."""
    stored = row.multiverse
    if stored is None:
        return {"cases": None, "flipped_by": "", "best_case": "", "best_case_verdict": "", "best_case_number": "",
                "multiverse": ""}
    return {"cases": stored.cases, "flipped_by": "; ".join(stored.flipped_by), "best_case": stored.best_case,
            "best_case_verdict": stored.best_case_verdict.outcome.value, "best_case_number": stored.best_case_number,
            "multiverse": row.multiverse_experiment}


@dataclass(frozen=True)
class Scorecard:
    """What the summaries of a reports folder decide together, read once through their schema: each paper's
    claims (``rows``), the summary of every published cell (``cells``, with the claim owning each and a link),
    each claim's tally of its cells and the claims as one table (``claims``); ``reports/summary.csv`` and
    ``reports/claims.csv`` are its exports (:attr:`cell_table`, :attr:`claims`), never read back."""

    summaries: dict[str, Summary]
    rows: dict[str, list[ClaimRow]]
    cells: pd.DataFrame
    tallies: dict[str, str]
    claims: pd.DataFrame
    papers: tuple[Paper, ...] = ()

    @property
    def criteria(self) -> list[dict]:
        """Per paper and over all, the claims meeting each replication criterion of those it applies to."""
        return shares({paper: [row.assessed for row in claims] for paper, claims in self.rows.items()})

    @property
    def effects(self) -> pd.DataFrame:
        """Every sized effect, the paper's against ours (:func:`effect_points`)."""
        return effect_points(self.rows)

    @property
    def surviving(self) -> tuple[float, float, float, int]:
        """The median share of the paper's effect that survives over claims, its 95 % bootstrap interval, and
        the claims behind it."""
        return surviving([row.assessed for claims in self.rows.values() for row in claims],
                         INFERENCE.bootstrap_resamples, INFERENCE.bootstrap_seed)

    @classmethod
    def of(cls, summaries: dict[str, Summary], papers: list[Paper], published: pd.DataFrame) -> "Scorecard":
        """The scorecard of ``summaries`` (:func:`~replication.evidence.summary.load_summaries`), judged
        against the ``published`` values."""
        rows = claim_rows(papers, summaries)
        cells = summary_table(published, summaries, experiment_configs(), owner_of_cells(papers, published))
        tallies = cell_tallies(cells)
        return cls(summaries, rows, cells, tallies, claims_frame(rows, cells, tallies), tuple(papers))

    @classmethod
    def read(cls, reports, published_values=None) -> "Scorecard":
        """The scorecard of the reports in folder ``reports`` (each experiment's summary, at the paper scale where
        there is one), the five papers' claims, judged against the published values ``published_values`` (the
        shipped file unless named)."""
        return cls.of(load_summaries(reports), list(load_papers()), load_published(str(published_path(published_values))))

    @property
    def cell_table(self) -> pd.DataFrame:
        """The summary of every published cell as ``summary.csv`` writes it (without the link's text)."""
        return self.cells.drop(columns=["link_text"])
