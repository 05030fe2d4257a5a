"""One experiment's page, drawn from its judgement (:func:`replication.evidence.judge.judge_experiment`): its
tables as CSV and HTML, its figures and a page tying them together; the files the caller wrote beside it (every
run and frame as tidy tables, the toolkits' results) linked.  Nothing is decided or stored as a decision here:
the caller writes ``summary.json`` with the figures drawn (:class:`Drawn`)."""

import platform
import sys
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml
import pandas as pd
from omegaconf import DictConfig

import replication
from replication import atomic
from replication.evidence.checks import Result
from replication.evidence.footage import Footage
from replication.evidence.judge import Judgement
from replication.evidence.settings import rules
from replication.report.figures import draw
from replication.report.pages.render import html_table, render
from replication.report.pages.scale import scale_note
from replication.report.pages.sequences import write_sequence_pages
from replication.scales import index_from
from replication.report.figures.style import NothingToDraw
from replication.evidence.figures import figure_specs

SHOWN = 12  # of the differences a user's request makes, those the page lists (the digest covers them all)


@dataclass(frozen=True)
class Shown:
    """What the page shows beside the judgement, from the caller that read the runs
    (:mod:`replication.report.experiments`): the folder, the published values judged against, the files written
    beside the page (the runs' tidy tables, the toolkits' results folders), what each scene is, the curve tables
    kept in place of the runs' series (the record's), the command that made the runs and the video they saw
    (:class:`~replication.evidence.footage.Footage`)."""

    out: Path
    published: pd.DataFrame
    footage: Footage
    files: list[str] = field(default_factory=list)
    results: list[str] = field(default_factory=list)
    scenes: list[dict] = field(default_factory=list)
    curves: dict[str, pd.DataFrame] = field(default_factory=dict)
    command: str = ""


@dataclass(frozen=True)
class Drawn:
    """What a page drew: its path and its figures (name, title, file, and link and beside where given), which
    the caller stores with the judgement's summary."""

    page: Path
    figures: tuple[dict[str, str], ...] = ()


def write_experiment_report(cfg: DictConfig, judged: Judgement, shown: Shown) -> Drawn:
    """Draw an experiment's page into ``shown.out`` (``<reports>/<experiment>/``, at the quick scale
    ``<reports>/quick/<experiment>/``) from its ``judged`` runs: its tables as CSV and HTML, its figures and the
    page; return what it drew (the caller stores the summary: :func:`replication.report.experiments.write_experiment`)."""
    experiment, records, summary, out = judged.experiment, judged.records, judged.summary, shown.out
    tables, figures, left_out = [], [], []
    for written in summary.tables:
        table = judged.tables[written["name"]]
        atomic.save(out / written["csv"], lambda tmp: table.written().to_csv(tmp, index=False))
        html = html_table(table.shown())
        atomic.write_text(out / f"{written['name']}.html", html)
        tables.append({**written, "html": html})
    for figure_spec in figure_specs(experiment) if len(records) else ():
        file = f"{figure_spec.name}.png"
        try:
            draw(records, figure_spec, experiment, out / file, shown.published, shown.curves.get(figure_spec.name),
                 footage=shown.footage)
        except NothingToDraw as reason:  # as a table none of whose conditions ran: left out, and said
            left_out.append(str(reason))
            continue
        link = {"link": figure_spec.linked} if figure_spec.linked else {}  # a file the figure wrote too
        beside = {"beside": figure_spec.beside} if figure_spec.beside else {}  # under that table
        figures.append({"name": figure_spec.name, "title": figure_spec.title, "file": file, **link, **beside})
    sequences = write_sequence_pages(records, experiment, out, shown.footage) if len(records) else []
    failures = Counter(summary.failed)
    unmatched = judged.unmatched
    page = out / "index.html"
    atomic.write_text(
        page,
        render(
            "experiment.html.j2",
            title=experiment.get("title", experiment["name"]),
            paper=experiment["paper"],
            scale=cfg.scale,
            n_records=summary.n_records,
            n_runs=summary.n_runs,
            failures=failures.most_common(),
            n_failed=failures.total(),
            tables=tables,
            files=shown.files,
            scenes=shown.scenes,
            figures=figures,
            left_out=left_out,
            results=shown.results,
            unmatched=html_table(unmatched[["table", "method", "metric", "condition", "value", "unit", "note"]])
            if len(unmatched)
            else None,
            rules=rules(),
            claims=_claims_shown(summary.claims),
            scale_note=scale_note(cfg.scale, list(summary.scale_changes)),
            provenance=_provenance(records),
            name=summary.name,
            home=index_from(summary.name, cfg.scale),  # the reports' index, from this page's folder
            changes=summary.own[:SHOWN],
            more_changes=max(len(summary.own) - SHOWN, 0),
            sweeps=sorted(p.stem for p in (out / "sweeps").glob("*.html")),
            sequences=sequences,
            command=shown.command,
            config=yaml.safe_dump(experiment, sort_keys=False),  # as run: at its scale, sequences located
            versions=_versions(),
        )
    )
    return Drawn(page, tuple(figures))


def _claims_shown(claims: dict[str, dict[str, Result]]) -> list[dict]:
    """Each claim reading tested on this experiment, with its checks, for the page."""
    return [{"id": claim, "reading": reading, "verdict": result.verdict, "checks": result.checks}
            for claim, readings in claims.items() for reading, result in readings.items()]


def _provenance(records: pd.DataFrame) -> list[dict]:
    """Which code and machine computed the stored runs: one row per distinct combination, its runs and dates."""
    columns = [c for c in ("code_digest", "git_commit", "git_dirty", "python_version", "numpy_version",
                           "scipy_version", "opencv_version", "numba_version", "machine") if c in records]
    if not columns or "computed_at" not in records:
        return []
    groups = records.assign(**{c: records[c].astype(str) for c in columns}).groupby(columns, sort=False)
    return [{**dict(zip(columns, key)), "runs": len(group),
             "computed": f"{group['computed_at'].min()[:16]} to {group['computed_at'].max()[:16]} UTC"}
            for key, group in groups]


def _versions() -> str:
    import hydra
    import joblib
    import scipy

    return "\n".join(
        [
            f"replication {replication.__version__}",
            f"python {platform.python_version()} ({sys.platform})",
            f"numpy {np.__version__}, scipy {scipy.__version__}, pandas {pd.__version__}",
            f"hydra-core {hydra.__version__}, joblib {joblib.__version__}",
        ]
    )
