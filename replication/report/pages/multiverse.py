"""A paper's claims under every reading: each claim's verdict in every universe of its multiverse.

A *case* is one universe (an alternative for each open choice, see
:mod:`replication.runner.multiverse`) tested with one of the claim's scoring
readings (``conf/claims/<paper>.yaml``).  Whether the claim's verdict depends
on a choice is decided by the choice's paired effect on the deciding
statistic (:mod:`replication.evidence.robustness`): *robust* unless some
alternative moves that statistic significantly (Holm across the alternatives)
and its verdict with it.  :class:`Robustness` gives each alternative's effect
with its interval and the best case for the paper: the case that comes
closest to the claim holding, with its number.
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from omegaconf import DictConfig, OmegaConf

from replication import atomic
from replication.evidence.claim_tests import ClaimTest
from replication.evidence.claims import Claim, evaluate, load_papers
from replication.evidence.multiverse import BASIS, READING, Case, Robustness
from replication.evidence.published import load_published, published_path
from replication.evidence.schema import Summary
from replication.evidence.settings import rules
from replication.evidence.statistics import said_level
from replication.paths import resolve
from replication.report.pages.render import render
from replication.report.pages.scale import scale_note
from replication.scales import index_from, report_folder
from replication.report.figures.style import OUTCOME_COLOURS
from replication.evidence.tables import TableKind, table_specs
from replication.runner.multiverse import Multiverse
from replication.runner.store import Store

def evaluate_multiverse(multiverse: Multiverse, store_of, published: pd.DataFrame) -> tuple[list[Robustness], int]:
    """Every claim of the paper tested in every universe with each of its readings on the multiverse's
    experiments (``store_of(experiment, universe)``: where that universe's runs of it are); and how many
    records were read (a run several universes share, in each)."""
    claims = [c for paper in load_papers() if paper.key == multiverse.paper for c in paper.claims]
    cases: dict[str, list[Case]] = {c.id: [] for c in claims}
    n_records = 0
    for universe in multiverse.universes:
        results = {}
        for name in multiverse.experiments:
            experiment = multiverse.experiment_configs[universe.name, name]
            records = store_of(name, universe).load(multiverse.runs[universe.name, name])
            n_records += len(records)
            tables = _tables(name, experiment, records, claims, published)
            for claim, readings in evaluate(name, experiment, records, tables, published).items():
                results.setdefault(claim, {}).update(readings)
        for claim in claims:
            for reading in claim.readings:
                stored = results.get(claim.id, {}).get(reading.name)
                if stored is not None:
                    scoring = ((BASIS, reading.compared_at), (READING, reading.name))
                    cases[claim.id].append(Case(universe.name, universe.picks + scoring, stored))
    return [Robustness(claim, tuple(cases[claim.id])) for claim in claims if cases[claim.id]], n_records


def _tables(name: str, experiment: dict, records: pd.DataFrame, claims: list[Claim], published: pd.DataFrame):
    """The tables the claims' ``cells`` readings on ``name`` judge, built from ``records`` (only those)."""
    wanted = {t for c in claims for r in c.readings if r.experiment == name
              for t in ClaimTest.of(r.test, experiment).tables}
    specs = [s for s in table_specs(experiment) if s.name in wanted]
    if records.empty:
        return {}
    return {s.name: TableKind.of(s, experiment, published).build(records) for s in specs}


def draw(robustness: list[Robustness], multiverse: Multiverse, path: Path) -> None:
    """A forest plot per claim: the deciding check of its default case, in every universe under the claim's
    first reading, with the interval of the test that decided it (its level in the panel's title), coloured by
    verdict; the claim's line (the paper's value, a bound, zero difference or an allowed margin) dashed."""
    path.unlink(missing_ok=True)  # a figure of runs since recomputed must not outlive them
    shown = [r for r in robustness if _headline(r)]
    if not shown:
        return
    rows = len(multiverse.universes)
    fig, axes = plt.subplots(len(shown), 1, figsize=(8, 0.6 + len(shown) * (0.9 + 0.28 * rows)), squeeze=False)
    for ax, claim in zip(axes[:, 0], shown):
        what = _headline(claim)
        first = claim.claim.readings[0].name
        reference, level = None, None  # the claim's line and interval level, from its checks (not the last claim's)
        for y, universe in enumerate(multiverse.universes):
            case = next((c for c in claim.cases if c.universe == universe.name and dict(c.picks)[READING] == first),
                        None)
            check = next((c for c in case.result.checks if c.what == what), None) if case else None
            if check is None or check.estimate is None or not np.isfinite(check.estimate.value):
                continue
            colour = OUTCOME_COLOURS[check.verdict.outcome.value]
            if check.estimate.defined:
                ax.plot([check.estimate.low, check.estimate.high], [y, y], color=colour, lw=2)
            ax.plot([check.estimate.value], [y], "o", color=colour)
            reference, level = check.reference, check.estimate.level
        if reference is not None:
            ax.axvline(reference, color="0.3", ls="--", lw=1)
        ax.set_yticks(range(rows), [u.name for u in multiverse.universes], fontsize=7)
        ax.invert_yaxis()
        title = f"{claim.claim.id}: {what}" + (f" ({said_level(level)})" if level else "")
        ax.set_title(title, fontsize=8, loc="left")
        ax.tick_params(axis="x", labelsize=7)
    handles = [plt.Line2D([], [], marker="o", color=colour, ls="", label=outcome)
               for outcome, colour in OUTCOME_COLOURS.items()]
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=7, frameon=False)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    atomic.save_figure(fig, path, dpi=110, bbox_inches="tight")  # universes' names can be long
    plt.close(fig)


def _headline(robustness: Robustness) -> str | None:
    """The check plotted for a claim: the one that decided its default case, if it has a number."""
    deciding = robustness.default.deciding
    return deciding.what if deciding and deciding.estimate is not None else None


def write_multiverse_report(cfg: DictConfig, multiverse: Multiverse, overrides: tuple[str, ...] = (),
                            store_of=None) -> Path:
    """``<reports>/<paper>_readings/`` (at the quick scale under ``<reports>/quick/``): the choices, the universes
    run, each claim's robustness with every case, the forest plot, and ``summary.json`` (under ``multiverse``) for
    the scorecard.  ``store_of(experiment, universe)`` holds the runs (the store by default; the paper-scale
    record's universe, or the record beneath the store: :mod:`replication.record.layer`)."""
    out = report_folder(resolve(cfg.reports), multiverse.name, cfg.scale)
    out.mkdir(parents=True, exist_ok=True)
    published = load_published(str(published_path(cfg.published_values)))
    store_of = store_of or (lambda name, universe: Store(resolve(cfg.store), name))
    robustness, n_records = evaluate_multiverse(multiverse, store_of, published)
    draw(robustness, multiverse, out / "readings.png")
    frame = pd.DataFrame([{"claim_id": r.claim.id, "universe": c.universe, **{k: v for k, v in c.picks},
                           "verdict": c.verdict.outcome.value, "why": c.verdict.why,
                           "number": c.deciding.number if c.deciding else ""} for r in robustness for c in r.cases])
    atomic.save(out / "cases.csv", lambda tmp: frame.to_csv(tmp, index=False))
    n_runs = sum(len(runs) for runs in multiverse.runs.values())  # per universe: a shared run in each
    page = out / "index.html"
    atomic.write_text(page, render(
        "multiverse.html.j2", title=cfg.experiment.get("title", multiverse.name), multiverse=multiverse,
        robustness=robustness, figure=(out / "readings.png").exists(), rules=rules(), n_runs=n_runs,
        home=index_from(multiverse.name, cfg.scale),
        scale_note=scale_note(cfg.scale), config=OmegaConf.to_yaml(cfg.experiment),
        command=" ".join([f"python -m replication experiment={multiverse.name} scale={cfg.scale}",  # what made it
                          *(o for o in overrides if not o.startswith(("experiment=", "scale=")))])))
    figures = ({"name": "readings", "file": "readings.png",
                "title": "Each claim's deciding number in every universe (its test's interval, coloured by verdict)"},)
    Summary(multiverse.name, cfg.experiment.get("title", multiverse.name), multiverse.paper, cfg.scale, n_records,
            n_runs, figures=figures if (out / "readings.png").exists() else (),
            multiverse={r.claim.id: r.as_result() for r in robustness}).write(out)
    return page
