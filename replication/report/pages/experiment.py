"""One experiment's report: its tables as CSV and HTML, its figures, a page tying them together, and every
run (``runs.parquet``, ``runs.csv``) and frame (``frames.parquet``) as tidy tables
(:mod:`replication.runner.results`)."""

import platform
import sys
from pathlib import Path

import numpy as np
import yaml
import pandas as pd
from omegaconf import DictConfig, OmegaConf

import replication
from replication import atomic
from replication.evidence.checks import Result
from replication.evidence.claims import evaluate, load_own_papers
from replication.evidence.schema import Summary
from replication.evidence.settings import rules
from replication.export import LAYOUTS, write_results
from replication.paths import resolve
from replication.report.figures import draw
from replication.evidence.published import cells, load_published, published_path
from replication.report.pages.render import html_table, render
from replication.report.pages.scale import scale_changes, scale_note
from replication.report.pages.sequences import write_sequence_pages
from replication.scales import index_from, report_folder
from replication.report.figures.style import NothingToDraw
from replication.evidence.figures import figure_specs
from replication.evidence.tables import Compared, TableKind, table_specs
from replication.scenes.factory import cached_sequence, scene_kind
from replication.runner.results import Results
from replication.runner.variant import SHOWN


def write_experiment_report(cfg: DictConfig, results: Results) -> Path:
    """Write ``<reports>/<experiment>/`` (at the quick scale ``<reports>/quick/<experiment>/``) from an
    experiment's stored ``results``; return the page's path."""
    experiment, runs, records, failures = results.experiment, results.runs, results.records, results.failures
    out = report_folder(resolve(cfg.reports), results.name, cfg.scale)
    out.mkdir(parents=True, exist_ok=True)
    published = load_published(str(published_path(cfg.published_values)))
    tables, figures, built, left_out = [], [], {}, []
    files = results.write_tables(out)
    results_folders = [f"results/{folder}/" for layout, folder in LAYOUTS.items()  # real OTB runs, for the toolkits
                       if "per_frame" in records and write_results(runs, records, out / "results", layout)]
    if len(records):
        for table_spec in table_specs(experiment):
            table = TableKind.of(table_spec, experiment, published).build(records)
            if table.empty:  # none of the table's conditions was run (a narrowed sweep, say)
                continue
            built[table_spec.name] = table
            csv = f"{table_spec.name}.csv"
            atomic.save(out / csv, lambda tmp: table.written().to_csv(tmp, index=False))
            html = html_table(table.shown())
            atomic.write_text(out / f"{table_spec.name}.html", html)
            tables.append({"name": table_spec.name, "title": table_spec.title, "html": html, "csv": csv,
                           "note": table.note})
        for figure_spec in figure_specs(experiment):
            file = f"{figure_spec.name}.png"
            try:
                draw(records, figure_spec, experiment, out / file, published, results.curves.get(figure_spec.name))
            except NothingToDraw as reason:  # as a table none of whose conditions ran: left out, and said
                left_out.append(str(reason))
                continue
            link = {"link": figure_spec.linked} if figure_spec.linked else {}  # a file the figure wrote too
            beside = {"beside": figure_spec.beside} if figure_spec.beside else {}  # under that table
            figures.append({"name": figure_spec.name, "title": figure_spec.title, "file": file, **link, **beside})
    sequences = write_sequence_pages(records, experiment, out) if len(records) else []
    compared = tuple(cell for table in built.values() for cell in table.cells)
    matched = {cell.published_index for cell in compared}
    # a user's own data, methods or settings judge no paper claim (the claims name the papers' data and
    # methods), only the user's own claims (claims_dir), by the same rules
    own = load_own_papers(resolve(cfg.claims_dir)) if results.own and cfg.get("claims_dir") else ()
    claims = evaluate(experiment["name"], experiment, records, built, published, own if results.own else None)
    changes = scale_changes(results.at_paper_scale, experiment)
    paper_tables = sorted({t for s in table_specs(experiment) if isinstance(s, Compared) for t in s.paper_tables})
    unmatched = cells(published, experiment["paper"], paper_tables)
    unmatched = unmatched.drop(index=list(matched), errors="ignore")
    page = out / "index.html"
    atomic.write_text(
        page,
        render(
            "experiment.html.j2",
            title=experiment.get("title", experiment["name"]),
            paper=experiment["paper"],
            scale=cfg.scale,
            n_records=len(records),
            n_runs=len(runs),
            failures=failures.most_common(),
            n_failed=failures.total(),
            tables=tables,
            files=files,
            scenes=_scenes(experiment, OmegaConf.to_container(cfg.experiment, resolve=True)),
            figures=figures,
            left_out=left_out,
            results=results_folders,
            unmatched=html_table(unmatched[["table", "method", "metric", "condition", "value", "unit", "note"]])
            if len(unmatched)
            else None,
            rules=rules(),
            claims=_claims_shown(claims),
            scale_note=scale_note(cfg.scale, changes),
            provenance=_provenance(records),
            name=results.name,
            home=index_from(results.name, cfg.scale),  # the reports' index, from this page's folder
            changes=results.changes[:SHOWN],
            more_changes=max(len(results.changes) - SHOWN, 0),
            sweeps=sorted(p.stem for p in (out / "sweeps").glob("*.html")),
            sequences=sequences,
            command=results.command,
            config=yaml.safe_dump(experiment, sort_keys=False),  # as run: at its scale, sequences located
            versions=_versions(),
        )
    )
    Summary(results.name, experiment.get("title", experiment["name"]), experiment["paper"], cfg.scale,
            len(records), len(runs), dict(failures), compared, claims, tuple(changes),
            tuple({k: t[k] for k in ("name", "title", "csv", "note")} for t in tables), tuple(figures),
            own=results.changes).write(out)
    return page


def _scenes(experiment: dict, written: dict) -> list[dict]:
    """What each scene of a tracking experiment is: real video, or a synthetic stand-in and for what; for a
    stand-in whose length depends on the scale, whether the quick video is the start of the paper's."""
    rows = []
    for name, spec in experiment.get("scenes", {}).items():
        kind = scene_kind(spec)
        if kind.real:
            first = spec.get("first", kind.counts_from) - kind.counts_from + 1  # counted from 1, as people do
            frames = f"frames {first}-{spec['last']}" if spec.get("last") else "all frames"
            rows.append({"name": name, "kind": f"real video ({kind.benchmark})",
                         "what": f"{kind.benchmark} sequence {spec['name']}, {frames}"})
        else:
            size = "x".join(str(v) for v in spec.get("size", []))
            what = spec.get("stand_in") or "synthetic scene"
            rows.append({"name": name, "kind": "synthetic stand-in",
                         "what": f"{what} ({size}, {spec.get('frames')} frames){_prefix(written['scenes'][name])}"})
    return rows


def _prefix(scene: dict) -> str:
    """Whether the quick scale's video of a scene is the first frames of the paper scale's (same seed)."""
    frames = scene.get("frames")
    if not isinstance(frames, dict) or not {"quick", "paper"} <= set(frames):
        return ""
    short, long = (cached_sequence({**scene, "frames": frames[s]}) for s in ("quick", "paper"))
    same = np.array_equal(short.truth, long.truth[: len(short.truth)])
    said = f"; the quick scale's {frames['quick']} frames are {'' if same else 'not '}the first {frames['quick']}"
    return f"{said} of the paper scale's {frames['paper']}" + ("" if same else " (another random walk, same seed)")


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
