"""``pf-replicate record [experiment=a,b] [store=...] [record=...]``: write the paper-scale record from the
store.

Each experiment's runs at the paper scale, as the runner expands them, are read from the store (failed
runs with their reason) into ``<record>/<experiment>/runs.parquet`` (:mod:`.runs`), and the tables its curve
figures draw into ``<record>/<experiment>/curves/<figure>.parquet``; a paper's multiverse
(``<paper>_readings``) universe by universe into ``<record>/<paper>_readings/universes/<universe>.parquet``.  An
experiment with a run neither stored nor failed is not written (run it first: the record holds whole
experiments), and the manifest (:mod:`.manifest`) is updated for those written.  A run the store lacks that
the record already holds as this code computes it (a paper-scale request read it from the record,
:mod:`.layer`) keeps its recorded row; an experiment none of whose runs the store holds stays as recorded,
and one with curve figures is recorded again only from a store that holds every run (the record keeps no
per-frame series to draw its curves from).  A table whose bytes do
not change keeps its manifest entry, date and commit, so regenerating the record changes only what
changed.
"""

import shutil
import sys
from pathlib import Path

import pandas as pd
import pyarrow as pa
from omegaconf import DictConfig

from replication.errors import ConfigError
from replication.evidence.figures import figure_specs
from replication.evidence.tables import TABLE_KINDS, table_specs
from replication.record.layer import SCALE, runs_source
from replication.record.manifest import Entry, Manifest
from replication.record.runs import (
    CURVES_DIR, RUNS_FILE, UNIVERSE, read_rows, row, runs_table, universe_path, write_table,
)
from replication.run import Run
from replication.runner.config import expand, experiment_at_scale
from replication.runner.curves import curve_table
from replication.runner.footage import SceneFootage
from replication.runner.multiverse import load
from replication.runner.store import CorruptRecord, Store


def kept_series(experiment: dict) -> tuple[str, ...]:
    """The per-frame series the experiment's tables are built from: the record keeps those alone."""
    return tuple(sorted({s for spec in table_specs(experiment) for s in TABLE_KINDS[spec.kind].reads}))


def stored_rows(runs: list[Run], store: Store, series: tuple[str, ...],
                recorded: dict[str, dict] | None = None) -> tuple[list[dict], int, int]:
    """The rows of ``runs`` from ``store`` (a failed run with its reason), else from ``recorded`` (run id ->
    the record's row of it, :func:`recorded_rows`); how many neither holds, and how many came from
    ``recorded``."""
    rows, missing, from_record = [], 0, 0
    for run in runs:
        try:
            stored = store.read(run)
        except CorruptRecord:
            stored = None
        failed = store.failure_path(run)
        failure = failed.read_text().strip() if stored is None and failed.exists() else None
        if stored is None and failure is None and run.run_id in (recorded or {}):
            rows.append(recorded[run.run_id])
            from_record += 1
        elif stored is None and failure is None:
            missing += 1
        else:
            rows.append(row(run, stored, failure, series))
    return rows, missing, from_record


def recorded_rows(record: Path, runs: list[Run], universe: tuple[str, str] | None = None) -> dict[str, dict]:
    """Run id -> the row of each of ``runs`` the record at ``record`` holds as this code computes it (its
    recorded key the run's), where the record's files of their experiment, or of their ``universe``, are sound
    (:func:`.layer.runs_source`)."""
    source = runs_source(record, runs[0].experiment, universe) if runs else None
    return {} if source is None else {run.run_id: found for run, found in source.found(runs)
                                      if found["run_key"] == run.key}


def write_experiment(cfg: DictConfig, store_root: Path, record: Path) -> Entry:
    """Write ``cfg.experiment``'s runs (``cfg.scale`` must be the paper's) into ``record``, and the tables its
    curve figures draw; its manifest entry.  Raises :class:`ConfigError` naming how many runs are missing
    when the store does not hold them all."""
    name, runs = cfg.experiment.name, expand(_at_paper_scale(cfg))
    experiment, store = experiment_at_scale(cfg), Store(store_root, cfg.experiment.name)
    rows, missing, from_record = stored_rows(runs, store, kept_series(experiment), recorded_rows(record, runs))
    _complete(name, missing, len(runs))
    if from_record == len(runs):  # nothing new in the store: as recorded
        return Manifest.read(record).experiments[name]
    curved = [spec.name for spec in figure_specs(experiment) if spec.curved]
    if from_record and curved:
        raise ConfigError(f"{name}: {from_record} of {len(runs)} runs are in the record only, which keeps no per-frame "
                          f"series for its curve figure {curved[0]!r}; compute them to record it: "
                          f"pf-replicate experiment={name} scale=paper skip_recorded=false")
    path = record / name / RUNS_FILE
    write_table(runs_table(rows), path)
    return Entry.of([path, *write_curves(experiment, store, runs, record / name / CURVES_DIR)], record, rows)


def write_multiverse(cfg: DictConfig, store_root: Path, record: Path) -> Entry:
    """Write each universe of a paper's multiverse whose runs the store holds into its own file (a row per
    run of each experiment it re-runs, its picks as ``universe.<choice>`` columns), so that a multiverse
    too long for one sitting is recorded universe by universe; the others are left as they are (a file
    written before stays), with one line each.  Its manifest entry: every universe file there is."""
    multiverse = load(_at_paper_scale(cfg))
    # the record's rows of every universe are read before any of its files is written: a file rewritten no longer
    # has the SHA-256 the manifest gives it until the manifest is, and the record of a damaged multiverse is not read
    recorded = {(universe.name, name): recorded_rows(record, multiverse.runs[universe.name, name],
                                                     (multiverse.name, universe.name))
                for universe in multiverse.universes for name in multiverse.experiments}
    kept = set()
    for universe in multiverse.universes:
        path = universe_path(record, multiverse.name, universe.name)
        kept.add(path)
        picks = {f"{UNIVERSE}{choice}": alternative for choice, alternative in universe.picks}
        rows, missing = [], 0
        for name in multiverse.experiments:
            series = kept_series(multiverse.experiment_configs[universe.name, name])
            found, absent, _ = stored_rows(multiverse.runs[universe.name, name], Store(store_root, name), series,
                                           recorded[universe.name, name])
            rows, missing = rows + [{**picks, **r} for r in found], missing + absent
        if missing:
            kept_as = "kept as recorded" if path.exists() else "not recorded"
            print(f"skipped: {multiverse.name}, universe {universe.name}: {missing} runs not in the store ({kept_as})",
                  file=sys.stderr)
        else:
            write_table(runs_table(rows), path)
    for stray in set(path.parent.glob("*.parquet")) - kept:  # a universe no longer in the design
        stray.unlink()
    written = sorted(p for p in kept if p.exists())
    if not written:
        raise ConfigError(f"{multiverse.name}: no universe has all its paper-scale runs in the store; run them first: "
                          f"pf-replicate experiment={multiverse.name} scale=paper")
    return Entry.of(written, record, [r for p in written for r in read_rows(p)], universes=len(written))


def _at_paper_scale(cfg: DictConfig) -> DictConfig:
    if cfg.scale != SCALE:
        raise ConfigError(f"the record holds the paper scale; got scale={cfg.scale}")
    return cfg


def _complete(name: str, missing: int, total: int) -> None:
    if missing:
        raise ConfigError(f"{name}: {missing} of {total} paper-scale runs are not in the store; run them first: "
                          f"pf-replicate experiment={name} scale=paper")


def write_curves(experiment: dict, store: Store, runs: list[Run], folder: Path) -> list[Path]:
    """The table of each of the experiment's curve figures (:mod:`replication.runner.curves`), from the
    runs' per-frame series in ``store`` (read only for an experiment with such a figure), as
    ``<folder>/<figure>.parquet`` (floats in single precision: drawn, not tested); the files written
    (those of figures no longer configured are removed)."""
    shutil.rmtree(folder, ignore_errors=True)
    specs = [spec for spec in figure_specs(experiment) if spec.curved]
    records = store.load(runs) if specs else pd.DataFrame()
    written = []
    for spec in specs if len(records) else []:
        table = curve_table(records, spec, experiment, SceneFootage())
        if len(table):
            table = table.astype({c: "float32" for c in table if table[c].dtype == "float64"})
            written.append(folder / f"{spec.name}.parquet")
            write_table(pa.Table.from_pandas(table, preserve_index=False), written[-1])
    return written


def write(cfgs: list[DictConfig], store_root: Path, record: Path, skip_incomplete: bool = False) -> Manifest:
    """Write each experiment or multiverse of ``cfgs`` and the manifest; the manifest.  With
    ``skip_incomplete`` one whose runs the store does not all hold is left as it is, with one line."""
    manifest = Manifest.read(record)
    for cfg in cfgs:
        writer = write_multiverse if "multiverse" in cfg.experiment else write_experiment
        try:
            entry = writer(cfg, store_root, record)
        except ConfigError as error:
            if not skip_incomplete:
                raise
            print(f"skipped: {error}", file=sys.stderr)
            continue
        manifest = manifest.with_entry(cfg.experiment.name, entry)
        manifest.write(record)  # after each: an experiment written is in the manifest, whatever comes next
        print(f"{cfg.experiment.name}: {entry.runs} runs ({entry.failed} failed), {entry.bytes / 1e6:.2f} MB",
              flush=True)
    return manifest
