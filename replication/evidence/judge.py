"""Judge, then draw: the one entry that turns an experiment's (or a paper's multiverse's) runs into its tables,
its claims' verdicts and its summary, as typed values; the report's pages only draw what it returns.

:func:`judge_experiment` builds the tables an experiment's report spec names, matches their rows with the
paper's published cells, tests every claim reading on the experiment and gives a :class:`Judgement`, whose
:class:`~replication.evidence.schema.Summary` is what ``summary.json`` stores (the page adds the figures it
drew).  :func:`judge_multiverse` tests every claim of a paper in every universe of its multiverse under each
of its readings and gives a :class:`MultiverseJudgement`.  Both take the runs as data (records, counts) and
the video they saw through a :class:`~replication.evidence.footage.Footage`, so nothing here reads a store,
opens a video or imports compiled code.
"""

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Protocol

import pandas as pd

from replication.evidence.claim_tests import ClaimTest
from replication.evidence.claims import Claim, Paper, evaluate, load_papers
from replication.evidence.footage import Footage
from replication.evidence.multiverse import BASIS, READING, Case, Robustness
from replication.evidence.published import cells
from replication.evidence.schema import Summary
from replication.evidence.tables import Compared, Table, TableKind, table_specs
from replication.scales import scale_changes


@dataclass(frozen=True)
class Judgement:
    """An experiment judged: its tables (by name, in the report spec's order; a table none of whose conditions
    was run is left out), the published cells of its paper's tables that no table of ours matched, and its
    summary (cells, claims, counts; no figures: the page adds those it draws)."""

    experiment: dict
    records: pd.DataFrame
    tables: dict[str, Table]
    unmatched: pd.DataFrame
    summary: Summary


def judge_experiment(name: str, experiment: dict, records: pd.DataFrame, *, scale: str, n_runs: int,
                     failed: dict[str, int], published: pd.DataFrame, footage: Footage,
                     changes: tuple[str, ...] = (), at_paper_scale: dict | None = None,
                     papers: tuple[Paper, ...] | None = None) -> Judgement:
    """Judge experiment ``name`` (its report's: ``<experiment>@<label>`` for a user's own data or settings)
    from its config as run at ``scale`` and the ``records`` of its runs (``n_runs`` asked for, ``failed`` per
    reason), against ``published``; ``changes``: what the request changed in the shipped experiment;
    ``at_paper_scale``: the same config at the paper's scale (what the scale changes); ``papers``: whose
    claims (the five papers' unless given: a user's own, or none)."""
    specs = table_specs(experiment)
    tables = {}
    for table_spec in specs if len(records) else ():
        table = TableKind.of(table_spec, experiment, published, footage).build(records)
        if not table.empty:  # none of the table's conditions was run (a narrowed sweep, say)
            tables[table_spec.name] = table
    compared = tuple(cell for table in tables.values() for cell in table.cells)
    claims = evaluate(experiment["name"], experiment, records, tables, published, papers)
    paper_tables = sorted({t for s in specs if isinstance(s, Compared) for t in s.paper_tables})
    unmatched = cells(published, experiment["paper"], paper_tables)
    unmatched = unmatched.drop(index=[cell.published_index for cell in compared], errors="ignore")
    shown = tuple({"name": s.name, "title": s.title, "csv": f"{s.name}.csv", "note": tables[s.name].note}
                  for s in specs if s.name in tables)
    summary = Summary(name, experiment.get("title", experiment["name"]), experiment["paper"], scale, len(records),
                      n_runs, dict(failed), compared, claims,
                      tuple(scale_changes(at_paper_scale or experiment, experiment)), shown, own=tuple(changes))
    return Judgement(experiment, records, tables, unmatched, summary)


class Universes(Protocol):
    """A paper's multiverse as the judge reads it (:class:`replication.runner.multiverse.Multiverse`)."""

    name: str
    paper: str
    universes: list  # each with ``name`` and ``picks``
    experiments: list[str]
    experiment_configs: dict  # (universe, experiment) -> the experiment's config in that universe
    runs: dict  # (universe, experiment) -> its runs


@dataclass(frozen=True)
class MultiverseJudgement:
    """A paper's claims across its multiverse: each claim's :class:`~replication.evidence.multiverse.Robustness`
    (its verdict in every case) and the summary (no figures: the page adds the one it draws)."""

    robustness: list[Robustness]
    summary: Summary


def judge_multiverse(multiverse: Universes, records_of: Callable[[str, object], pd.DataFrame], *, title: str,
                     scale: str, published: pd.DataFrame, footage: Footage) -> MultiverseJudgement:
    """Every claim of the multiverse's paper tested in every universe with each of its readings on the
    multiverse's experiments (``records_of(experiment, universe)``: the records of that universe's runs of it);
    the summary counts the records read (a run several universes share, in each) and the runs (likewise)."""
    claims = [c for paper in load_papers() if paper.key == multiverse.paper for c in paper.claims]
    cases: dict[str, list[Case]] = {c.id: [] for c in claims}
    n_records = 0
    for universe in multiverse.universes:
        results = {}
        for name in multiverse.experiments:
            experiment = multiverse.experiment_configs[universe.name, name]
            records = records_of(name, universe)
            n_records += len(records)
            tables = _claimed_tables(name, experiment, records, claims, published, footage)
            for claim, readings in evaluate(name, experiment, records, tables, published).items():
                results.setdefault(claim, {}).update(readings)
        for claim in claims:
            for reading in claim.readings:
                stored = results.get(claim.id, {}).get(reading.name)
                if stored is not None:
                    scoring = ((BASIS, reading.compared_at), (READING, reading.name))
                    cases[claim.id].append(Case(universe.name, universe.picks + scoring, stored))
    robustness = [Robustness(claim, tuple(cases[claim.id])) for claim in claims if cases[claim.id]]
    n_runs = sum(len(runs) for runs in multiverse.runs.values())  # per universe: a shared run in each
    summary = Summary(multiverse.name, title, multiverse.paper, scale, n_records, n_runs,
                      multiverse={r.claim.id: r.as_result() for r in robustness})
    return MultiverseJudgement(robustness, summary)


def _claimed_tables(name: str, experiment: dict, records: pd.DataFrame, claims: Iterable[Claim],
                    published: pd.DataFrame, footage: Footage) -> dict[str, Table]:
    """The tables the claims' ``cells`` readings on ``name`` judge, built from ``records`` (only those)."""
    wanted = {t for c in claims for r in c.readings if r.experiment == name
              for t in ClaimTest.of(r.test, experiment).tables}
    specs = [s for s in table_specs(experiment) if s.name in wanted]
    if records.empty:
        return {}
    return {s.name: TableKind.of(s, experiment, published, footage).build(records) for s in specs}
