"""An experiment's (or a paper's multiverse's) report from its stored runs: read (:mod:`replication.runner`),
judged (:mod:`replication.evidence.judge`), then drawn (:mod:`replication.report.pages`).  The one path the
command line and the report's command take, so that a verdict is decided in one place and a page only draws
it; what needs video or compiled code reaches both through one
:class:`~replication.runner.footage.SceneFootage`."""

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from omegaconf import DictConfig, OmegaConf

from replication.evidence.claims import load_own_papers
from replication.evidence.judge import judge_experiment, judge_multiverse
from replication.evidence.published import load_published, published_path
from replication.export import LAYOUTS, write_results
from replication.paths import resolve
from replication.report.pages.experiment import Shown, write_experiment_report
from replication.report.pages.multiverse import write_multiverse_report
from replication.runner.footage import SceneFootage
from replication.runner.multiverse import Multiverse
from replication.runner.results import Results
from replication.runner.store import Store
from replication.scales import report_folder


def write_experiment(cfg: DictConfig, results: Results) -> Path:
    """Judge an experiment's stored ``results`` and write its report folder (``<reports>/<experiment>/``, at the
    quick scale ``<reports>/quick/<experiment>/``): every run (``runs.parquet``, ``runs.csv``) and frame
    (``frames.parquet``) as tidy tables, a real OTB experiment's results for the toolkits, then its page; return
    the page's path."""
    footage = SceneFootage()
    published = load_published(str(published_path(cfg.published_values)))
    # a user's own data, methods or settings judge no paper claim (the claims name the papers' data and
    # methods), only the user's own claims (claims_dir), by the same rules
    papers = (load_own_papers(resolve(cfg.claims_dir)) if cfg.get("claims_dir") else ()) if results.own else None
    judged = judge_experiment(results.name, results.experiment, results.records, scale=cfg.scale,
                              n_runs=len(results.runs), failed=results.failures, published=published,
                              footage=footage, changes=results.changes, at_paper_scale=results.at_paper_scale,
                              papers=papers)
    out = report_folder(resolve(cfg.reports), results.name, cfg.scale)
    out.mkdir(parents=True, exist_ok=True)
    files = results.write_tables(out)
    exported = [f"results/{folder}/" for layout, folder in LAYOUTS.items()  # real OTB runs, for the toolkits
                if "per_frame" in results.records
                and write_results(results.runs, results.records, out / "results", layout)]
    scenes = footage.described(results.experiment, OmegaConf.to_container(cfg.experiment, resolve=True))
    drawn = write_experiment_report(cfg, judged, Shown(out, published, footage, files, exported, scenes,
                                                       results.curves, results.command))
    replace(judged.summary, figures=drawn.figures).write(out)  # the judgement, with the figures drawn of it
    return drawn.page


def write_multiverse(cfg: DictConfig, multiverse: Multiverse, overrides: tuple[str, ...] = (),
                     store_of: Callable[[str, object], Store] | None = None) -> Path:
    """Judge a paper's multiverse from its universes' stored runs and write its report; ``store_of(experiment,
    universe)`` holds the runs (the store by default; the paper-scale record's universe, or the record beneath
    the store: :mod:`replication.record.layer`)."""
    store_of = store_of or (lambda name, universe: Store(resolve(cfg.store), name))
    judged = judge_multiverse(
        multiverse, lambda name, universe: store_of(name, universe).load(multiverse.runs[universe.name, name]),
        title=cfg.experiment.get("title", multiverse.name), scale=cfg.scale,
        published=load_published(str(published_path(cfg.published_values))), footage=SceneFootage())
    drawn = write_multiverse_report(cfg, multiverse, judged, overrides)
    replace(judged.summary, figures=drawn.figures).write(drawn.page.parent)
    return drawn.page
