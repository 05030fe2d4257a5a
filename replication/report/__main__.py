"""``python -m replication.report [scale=quick|paper] [experiment=a,b] [pdf=false] [screenshot=true] [source=record]``:
rebuild reports from stored runs only (at the default scale, quick, unless ``scale=`` says otherwise; at the
paper scale, with the record's runs beneath the store's as a run reads them: :mod:`replication.record.layer`).

``source=record`` draws the paper-scale record's reports instead (:mod:`replication.record`: every
experiment it holds, at the paper scale, into ``<reports>/record/``): tables, verdicts and the figures
drawn from runs' metrics; a figure drawn from per-frame series the record does not keep is left out, and
its page says so.

``python -m replication.report experiment=<name> sweep=<key>=v1,v2,... [metric=<column>]``
instead draws a Hydra multirun's sweep of one config value (``replication.report.pages.sweep``).

Nothing is run: each experiment's report is redrawn from the records in the
store, ``reports/index.html`` links them under the summary of every published
cell, and ``reports/replication.pdf`` gathers the same tables and figures
(``pdf=false`` skips it).  ``screenshot=true`` also saves headless Chromium's
view of the index as ``reports/screenshot.png`` (where Chromium is installed).
A bar counts the experiments drawn (``progress=false`` hides it).
"""

import shutil
import sys
from dataclasses import dataclass
from pathlib import Path

from hydra import compose, initialize_config_dir
from joblib import Parallel, delayed
from tqdm.auto import tqdm

from replication import atomic
from replication.arguments import read
from replication.environment import variables
from replication.errors import ConfigError, fail
from replication.evidence.published import published_path
from replication.evidence.scorecard import Scorecard
from replication.evidence.settings import configure
from replication.paths import CONF_DIR, HOME_VARIABLE, experiment_names, project_dir, resolve
from replication.record.manifest import MANIFEST, PAGES, Manifest, read_profile
from replication.record.layer import beneath, reader, universes_beneath
from replication.record.runs import Record
from replication.report.findings import Drawn, drawn_inputs, inputs, write_html, write_pages
from replication.report.findings import render as render_findings
from replication.report.experiments import write_experiment, write_multiverse
from replication.report.pages.effects import FIGURE as EFFECTS
from replication.report.pages.index import write_index
from replication.report.pages.recorded import STATUS, write_status
from replication.runner.config import expand
from replication.runner.multiverse import load as load_multiverse
from replication.runner.preflight import check_yaml
from replication.runner.results import Results
from replication.runner.store import Store
from replication.scales import report_folder

SCREENSHOT = "screenshot.png"
PICTURE = "scorecard.png"  # the record's first page beside its findings (the README shows it)
README_PATH = "README.md"  # whose part on the record (its size, what made it, what each part took) findings renders
SOURCES = ("store", "record")


@dataclass(frozen=True)
class Options:
    """The command's own settings; every other argument is a setting of the config (Hydra's)."""

    experiment: tuple[str, ...] | None = None  # every experiment by default
    pdf: bool = True
    screenshot: bool = False
    sweep: str | None = None  # <key>=v1,v2,...: a multirun's sweep
    metric: str | None = None  # the sweep's column
    source: str = "store"  # or record


def main(argv: list[str]) -> None:
    if {"--help", "-h"} & set(argv):
        print(__doc__.strip())
        return
    options, overrides = read(argv, Options, "report", handed=("*",))
    chosen = options.experiment is not None
    names = options.experiment if chosen else experiment_names()
    unknown = sorted(set(names) - set(experiment_names()))
    if unknown:
        fail(f"unknown experiment {unknown[0]!r}; known: {', '.join(experiment_names())}")
    if options.sweep is not None:
        if len(names) != 1:
            fail("sweep= needs one experiment=<name>: the one the multirun ran")
        return report_sweep(names[0], options.sweep, options.metric, overrides)
    if options.metric is not None:
        fail("metric= only goes with sweep=")
    source = options.source
    if source not in SOURCES:
        fail(f"source must be one of {', '.join(SOURCES)}, got {source!r}")
    if source == "record":
        names, overrides = recorded_experiments(names, overrides, chosen)
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):  # the settings: workers, folders
        cfg = compose("config", overrides=[o for o in overrides if not o.lstrip("+~").startswith("experiment.")])
    try:  # each experiment's pages on its own worker (the order of the output is the experiments')
        pages = Parallel(n_jobs=cfg.n_jobs, return_as="generator")(
            delayed(draw)(name, overrides, source, chosen, project_dir()) for name in names)
        drawn = list(tqdm(pages, total=len(names), desc="pages", unit="experiment", disable=not cfg.progress,
                          mininterval=1.0))
    except ConfigError as error:
        fail(str(error))
    stale = {}  # drawn from the record: per experiment, its recorded runs that other code made
    designed = {}  # per multiverse, its universes by design (the record may hold fewer)
    for name, page, stale_runs, universes in drawn:
        if page is not None:
            print(f"{name}: {page}")
        if stale_runs is not None:
            stale[name], designed[name] = stale_runs, universes
    reports = resolve(cfg.reports)
    if source == "record":
        held = resolve(cfg.record)
        drawn_from = drawn_inputs(inputs(held, resolve(cfg.findings) / "templates", published_path(cfg.published_values)))
        print(f"status: {write_status(reports, Manifest.read(held), stale, designed, drawn_from, read_profile(held))}")
    if options.pdf:
        from replication.report.pdf import write_pdf

        print(f"pdf: {write_pdf(reports, Scorecard.read(reports, cfg.published_values))}")
    index = write_index(reports, Scorecard.read(reports, cfg.published_values))
    templates = resolve(cfg.findings) / "templates"
    if source == "record" and templates.is_dir():  # a clone's docs/findings/templates (none installed)
        try:  # rendered from the summaries the index read, then linked from it
            for page in write_html(render_findings(Drawn(reports, cfg.published_values), templates),
                                   reports / "findings"):
                print(f"findings: {page}")
            index = write_index(reports, Scorecard.read(reports, cfg.published_values))
        except LookupError as error:
            print(f"findings: not drawn: {error}", file=sys.stderr)
    print(f"index: {index}")
    if options.screenshot:
        from replication.report.pages.render import browser, open_in_browser

        if browser() is None:
            print("screenshot: skipped, no Chromium on the PATH (apt-get install chromium)",
                  file=sys.stderr)
        else:
            seen = open_in_browser(index, reports / SCREENSHOT)
            print(f"screenshot: {seen['screenshot']}")
            for line in seen["console"]:
                print(f"console: {line}", file=sys.stderr)


def draw(name: str, overrides: list[str], source: str, chosen: bool,
         home: Path) -> tuple[str, Path | None, int | None, int]:
    """Experiment (or multiverse) ``name``'s pages, from the store or the record (``source``), relative paths
    taken from the project directory ``home``: its name, its page (None where its config is broken and it was
    not ``chosen`` by name: skipped, and said), and from the record how many of its recorded runs other code
    made and a multiverse's universes by its design (from the store: None and 0; an experiment has 0
    universes)."""
    # a pool's worker, started for an earlier call, keeps the environment it was started with: relative paths
    # taken from ``home`` as the caller takes them
    with (variables({HOME_VARIABLE: str(home)}),
          initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3")):
        try:
            check_yaml(CONF_DIR / "experiment" / f"{name}.yaml")
        except ConfigError as error:
            if chosen:  # named on the command line: the user wants to know
                raise
            print(f"skipped: {error}", file=sys.stderr)  # one broken file never breaks the others
            return name, None, None, 0
        cfg = compose("config", overrides=[f"experiment={name}", *overrides])
        configure(cfg.inference)
        if "multiverse" in cfg.experiment and source == "record":  # every universe's recorded runs
            multiverse, record = load_multiverse(cfg), Record(resolve(cfg.record))
            page = write_multiverse(cfg, multiverse, tuple(overrides),
                                    lambda name, u: record.universe(multiverse.name, u.name))
            return name, page, record.stale_universes(multiverse), len(multiverse.universes)
        if "multiverse" in cfg.experiment:  # a paper's readings: every universe's stored runs (at paper scale,
            multiverse = load_multiverse(cfg)  # the record's beneath them, as the run read them)
            return name, write_multiverse(cfg, multiverse, tuple(overrides),
                                          reader(*universes_beneath(cfg, multiverse))), None, 0
        if source == "record":
            store = Record(resolve(cfg.record))
            results = Results.of(cfg, expand(cfg), store, tuple(overrides), store.curves(name))
            return name, write_experiment(cfg, results), len(store.stale(results.runs)), 0
        runs = expand(cfg)
        held = beneath(cfg, runs, Store(resolve(cfg.store), name))  # at paper scale, as the run read them
        results = Results.of(cfg, runs, held, tuple(overrides), held.curves)
        return name, write_experiment(cfg, results), None, 0


def findings(argv: list[str]) -> None:
    """``pf-replicate findings [record=record] [reports=reports] [findings=docs/findings] [readme=README.md]``:
    each paper's findings rendered from the record into ``<findings>/<paper>.md``, and the README's part on
    the record between its marks (:mod:`replication.report.findings`), the record's
    pages drawn first (into ``<reports>/record``) unless they were drawn from this very record by this code;
    when drawn, their first page's picture too (``<findings>/scorecard.png``, where Chromium is installed) and
    the effect picture (``<findings>/effects.png``)."""
    if {"--help", "-h"} & set(argv):
        print(findings.__doc__)
        return
    settings = _settings(argv)
    record, out = resolve(settings["record"]), resolve(settings["findings"])
    if not (record / MANIFEST).exists():
        fail(f"{record}: no record here (make record writes one from a paper-scale store)")
    drawn = Drawn(resolve(settings["reports"]) / PAGES, settings["published_values"])
    rendered_from = inputs(record, out / "templates", published_path(settings["published_values"]))
    if drawn_pages(record, argv) is None:  # another record, configs or code
        (drawn.folder / SCREENSHOT).unlink(missing_ok=True)  # never an older drawing's picture
        main(["source=record", "pdf=false", "screenshot=true", *argv])
        if (drawn.folder / SCREENSHOT).exists():  # the scorecard's picture, where Chromium is installed
            atomic.save(out / PICTURE, lambda tmp: shutil.copyfile(drawn.folder / SCREENSHOT, tmp))
            print(f"findings: {out / PICTURE}")
        if (drawn.folder / EFFECTS).exists():  # the effect picture the index drew (none: no sized claim)
            atomic.save(out / EFFECTS, lambda tmp: shutil.copyfile(drawn.folder / EFFECTS, tmp))
            print(f"findings: {out / EFFECTS}")
    try:
        pages = render_findings(drawn, out / "templates")
        written = write_pages(pages, out, rendered_from, resolve(settings.get("readme", README_PATH)))
    except LookupError as error:
        fail(str(error))
    for page in written:
        print(f"findings: {page}")


def drawn_pages(record: Path, overrides: list[str]) -> Path | None:
    """``<reports>/record`` where it holds ``record``'s pages drawn by this code from these configs and published
    values (``report source=record`` wrote them); None where it does not."""
    settings = _settings(overrides)
    folder = resolve(settings["reports"]) / PAGES
    rendered_from = inputs(record, resolve(settings["findings"]) / "templates",
                           published_path(settings["published_values"]))
    drawn_from = Drawn(folder).status.get("drawn_from") if (folder / STATUS).exists() else None
    return folder if drawn_from == drawn_inputs(rendered_from) else None


def recorded_experiments(names: list[str], overrides: list[str], chosen: bool) -> tuple[list[str], list[str]]:
    """The experiments to draw from the record (those it holds, of ``names``) and the overrides that draw
    them: the paper scale, into ``<reports>/record``."""
    settings = _settings(overrides)
    held = Manifest.read(resolve(settings["record"])).experiments
    if not held:
        fail(f"{resolve(settings['record'])}: no record here (make record writes one from a paper-scale store)")
    if chosen and set(names) - set(held):
        fail(f"the record holds no {sorted(set(names) - set(held))[0]!r}; it holds {', '.join(sorted(held))}")
    reports = Path(settings["reports"]) / PAGES
    kept = [o for o in overrides if o.partition("=")[0] not in ("scale", "reports")]
    return [name for name in names if name in held], [*kept, "scale=paper", f"reports={reports}"]


def _settings(overrides: list[str]) -> dict:
    """The top-level settings of ``conf/config.yaml`` with ``key=value`` overrides, without Hydra."""
    from omegaconf import OmegaConf

    return {**OmegaConf.load(CONF_DIR / "config.yaml"), **dict(o.partition("=")[::2] for o in overrides)}


def report_sweep(name: str, sweep: str, metric: str | None, overrides: list[str]) -> None:
    from hydra.errors import HydraException
    from omegaconf import OmegaConf
    from omegaconf.errors import OmegaConfBaseException

    from replication.report.pages.sweep import default_metric, parse_sweep, sweep_records, write_sweep_report
    from replication.scales import at_scale

    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        try:
            key, values = parse_sweep(sweep)
            records, missing = sweep_records(
                key, values,
                compose=lambda extra: compose("config", overrides=[f"experiment={name}", *overrides, *extra]),
                expand=expand,
                load=lambda cfg, runs: Store(resolve(cfg.store), name).load(runs),
            )
            cfg = compose("config", overrides=[f"experiment={name}", *overrides])
            experiment = at_scale(OmegaConf.to_container(cfg.experiment, resolve=True), cfg.scale)
            if records.empty:
                fail(f"{name}: no stored runs for any value of {key}; run the multirun first: "
                     f"python -m replication -m experiment={name} {' '.join(overrides)} {sweep}")
            command = " ".join(["python -m replication.report", f"experiment={name}", *overrides, f"sweep={sweep}"]
                               + ([f"metric={metric}"] if metric else []))
            results = Results.of(cfg, expand(cfg), Store(resolve(cfg.store), name), tuple(overrides))
            page = write_sweep_report(records, key, metric or default_metric(experiment), experiment,
                                      report_folder(resolve(cfg.reports), results.name, cfg.scale) / "sweeps",
                                      missing, command)
            write_experiment(cfg, results)  # now linking the sweep
        except (ConfigError, HydraException, OmegaConfBaseException) as error:  # a bad key, value or metric
            fail(str(error).splitlines()[0])
    for line in missing:
        print(f"missing: {line}", file=sys.stderr)
    print(f"sweep: {page}")


if __name__ == "__main__":
    main(sys.argv[1:])
