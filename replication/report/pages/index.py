"""``reports/index.html``: the scorecard of every paper's claims, every published cell against ours,
then every experiment with a report, linked.

Each scale's reports live apart (:func:`~replication.scales.report_folder`: ``<name>/`` at the paper scale,
``quick/<name>/`` at the quick one); the scorecard reads an experiment's paper-scale report where there is one,
else its quick one, and says which beside each verdict; the tables of experiments list both.

The scorecard (:mod:`replication.evidence.scorecard`) is also written as
``reports/claims.csv``, and the summary of every published cell
(:mod:`replication.evidence.summary`) as ``reports/summary.csv``.
"""

import datetime
from pathlib import Path

import replication
from replication import atomic
from replication.paths import experiment_names
from replication.record.manifest import PAGES
from replication.report.pages import effects, glance
from replication.report.pages.recorded import recorded
from replication.report.pages.render import render
from replication.report.pages.scale import scale_note
from replication.scales import QUICK_REPORTS, SCALES, page_link
from replication.evidence.criteria import CRITERIA
from replication.evidence.scorecard import Scorecard, tally
from replication.evidence.schema import Summary
from replication.evidence.summary import counts, load_summaries
from replication.evidence.settings import rules

TITLE = "Particle-filter tracking papers: replication report"


def _scale_note(summaries: dict[str, Summary]) -> str | None:
    """The banner when any verdict on the scorecard comes from a report below the paper's scale (each
    experiment's page lists its changes)."""
    quick = [name for name, s in summaries.items() if s.scale != "paper"]
    if not quick:
        return None
    return (f"The verdicts of {len(quick)} of {len(summaries)} experiments are at the quick scale (their pages: "
            f"{QUICK_REPORTS}/), each marked so beside it. {scale_note('quick')} Each experiment's page lists what "
            f"quick changes for it.")


def _entry(name: str, summary: Summary) -> dict:
    """A report's row in the index's tables of experiments."""
    return {"name": name, "link": page_link(summary.name, summary.scale), "title": summary.title,
            "paper": summary.paper, "scale": summary.scale,
            "n_records": summary.n_records, "n_runs": summary.n_runs, "failed": summary.failed,
            "verdicts": ", ".join(f"{k}: {v}" for k, v in sorted(summary.verdicts.items())) or "-",
            "ablation": "ablation" in name,  # the studies on top of the papers get their own section
            "multiverse": bool(summary.multiverse),  # so do the papers' readings
            "own": summary.own}  # and a user's own data or settings


def _findings(reports: Path, paper: str) -> str | None:
    """The link to the paper's findings at the papers' scale, from ``reports`` (the record's pages or the
    report above them), where they were drawn."""
    for link in (f"findings/{paper}.html", f"{PAGES}/findings/{paper}.html"):
        if (reports / link).exists():
            return link
    return None


def write_index(reports: Path, card: Scorecard) -> Path:
    """Draw ``reports/index.html`` around ``card``, the scorecard its caller read from the reports' summaries
    (:meth:`~replication.evidence.scorecard.Scorecard.read`), and write its exports (``summary.csv``,
    ``claims.csv``); return the page's path."""
    reports = Path(reports)
    summaries, papers = card.summaries, list(card.papers)  # each experiment's summary at one scale
    missing = [name for name in experiment_names() if name not in summaries]
    pages = {scale: load_summaries(reports, scales=(scale,)) for scale in SCALES}  # every page, at both scales
    experiments = [_entry(name, pages[scale][name]) for name in experiment_names() for scale in SCALES
                   if name in pages[scale]]
    own = [_entry(name, summary) for scale in SCALES
           for name, summary in load_summaries(reports, own=True, scales=(scale,)).items()]
    rows, cells, tallies = card.rows, card.cells, card.tallies
    record = recorded(reports, papers)
    reports.mkdir(parents=True, exist_ok=True)
    atomic.save(reports / "summary.csv", lambda tmp: card.cell_table.to_csv(tmp, index=False))  # exports, never read
    atomic.save(reports / "claims.csv", lambda tmp: card.claims.to_csv(tmp, index=False))
    glance.draw(glance.lines(papers, rows, record["claims"] if record else None), reports / glance.FIGURE)
    drawn_effects = effects.draw(card, reports / effects.FIGURE)
    page = reports / "index.html"
    atomic.write_text(
        page,
        render(
            "index.html.j2",
            title=TITLE,
            experiments=experiments,
            own=own,
            missing=missing,
            cells=cells.to_dict("records"),
            papers=[{"paper": paper, "claims": rows[paper.key], "tally": tally(rows[paper.key]),
                     "cells": int((cells["paper"] == paper.key).sum()), "findings": _findings(reports, paper.key)}
                    for paper in papers],
            scale_note=_scale_note(summaries),
            links={name: page_link(s.name, s.scale) for name, s in summaries.items()},  # the scorecard's evidence
            record=record,
            tallies=tallies,
            criteria=CRITERIA,
            shares=card.criteria,
            per_claim=[row for paper in papers for row in rows[paper.key]],
            effects={"drawn": drawn_effects is not None, "file": effects.FIGURE, "alt": effects.ALT,
                     "surviving": effects.surviving_said(card)},
            rules=rules(),
            counts=counts(cells, summaries),
            benchmark=(reports / "benchmark" / "index.html").exists(),
            calibration=(reports / "calibration" / "index.html").exists(),
            pdf=(reports / "replication.pdf").exists(),
            generated=datetime.date.today().isoformat(),
            version=replication.__version__,
        )
    )
    return page
