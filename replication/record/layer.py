"""The paper-scale record as a read-only layer beneath the store (``skip_recorded``, at the paper scale).

A run the record holds as this code computes it (its recorded key is the run's, :meth:`.runs.Record.found`)
is as good as computed: a paper-scale request reads it from the record and computes only the runs the
record lacks (:func:`beneath`).  The record is read only where its experiment's files still have the
SHA-256 its manifest gives them (:meth:`.manifest.Entry.damaged`); a damaged file is named in one line and
its runs are computed.  The store stays on top: a run it holds, sound or failed, is read from it.  Nothing
is copied into the store, so the store holds only what this machine computed.

The record keeps of a run its metrics, provenance and the per-frame series a table of its experiment reads
(:mod:`.runs`); so where any run is read from it, the other series are left out of the stored runs too,
and a figure drawn from them says it is not drawn, unless the record's curve table of it covers exactly
these runs (every run recorded, as many as the record holds).
"""

import sys
from collections import Counter
from functools import lru_cache
from pathlib import Path

import pandas as pd
from omegaconf import DictConfig

from replication.paths import resolve
from replication.record.manifest import MANIFEST, Entry, Manifest
from replication.record.runs import FAILURE, Record
from replication.run import Run
from replication.runner.results import SERIES
from replication.runner.store import CorruptRecord, Store

SCALE = "paper"  # the record's scale


class Layered:
    """``store`` with ``record`` beneath it: the runs named in ``recorded`` (held by the record as this code
    computes them, not by the store) are read from the record, every other run from the store.  Answers
    :meth:`load`, :meth:`failures` and :meth:`read` as :class:`~replication.runner.store.Store` does."""

    def __init__(self, store: Store, record: Record | None = None, recorded: frozenset[str] = frozenset(),
                 curves: dict[str, pd.DataFrame] | None = None):
        self.store, self.record, self.recorded, self.curves = store, record, recorded, curves or {}
        self.directory = store.directory

    def computed(self, runs: list[Run]) -> list[Run]:
        """The runs of ``runs`` the store is to hold: those not read from the record."""
        return [run for run in runs if run.run_id not in self.recorded]

    def read(self, run: Run) -> dict | None:
        """``run``'s record: the store's (None where it has none, or a damaged one), else the record's row."""
        if run.run_id not in self.recorded:
            try:
                return self.store.read(run)
            except CorruptRecord:
                return None
        found = self.record.found([run])
        return {**found[0][1], **run.identity()} if found and found[0][1].get(FAILURE) is None else None

    def load(self, runs: list[Run]) -> pd.DataFrame:
        """The records of ``runs``, one row each (:meth:`Store.load`): the store's, then the record's; where
        any is the record's, only the per-frame series the record keeps."""
        from_record = [run for run in runs if run.run_id in self.recorded]
        stored = self.store.load(self.computed(runs))
        if not from_record:
            return stored
        recorded = self.record.load(from_record)
        if stored.empty:
            return recorded
        stored = stored.drop(columns=[s for s in SERIES if s in stored and s not in recorded])
        return pd.concat([stored, recorded], ignore_index=True)

    def failures(self, runs: list[Run]) -> Counter:
        """How many of ``runs`` failed, per reason: in the store, and in the record for those read from it."""
        from_record = [run for run in runs if run.run_id in self.recorded]
        return self.store.failures(self.computed(runs)) + (self.record.failures(from_record) if from_record
                                                           else Counter())


def reads_record(cfg: DictConfig) -> bool:
    """Whether a request reads the record beneath the store: at the paper scale, unless ``skip_recorded=false``."""
    return bool(cfg.get("skip_recorded")) and cfg.scale == SCALE


def beneath(cfg: DictConfig, runs: list[Run], store: Store, universe: tuple[str, str] | None = None) -> Layered:
    """``store`` with the record ``cfg.record`` beneath it for ``runs`` (of one experiment): the store alone
    below the paper scale, with ``skip_recorded=false``, where there is no record, where the record's files of
    the experiment are damaged (said once, on stderr), or where it holds none of the runs as this code
    computes them.  For the runs of ``universe`` (a multiverse's name and one of its universes') the record's
    file of that universe is read too, for the runs the experiment's own files lack: a universe the record
    holds in part (its multiverse grown by a repetition or a swept value) computes only what it lacks."""
    if not runs or not reads_record(cfg):
        return Layered(store)
    root, name = resolve(cfg.record), runs[0].experiment
    source = runs_source(root, name, universe)
    if source is None:
        return Layered(store)
    held = {run.run_id for run, row in source.found(runs) if row["run_key"] == run.key}
    recorded = frozenset(run.run_id for run in runs if run.run_id in held
                         and not (store.path(run).exists() or store.failure_path(run).exists()))
    entry, record = checked(root, name), Record(root)  # the experiment's curve tables: of exactly its runs
    whole = bool(recorded) and entry is not None and len(runs) == entry.runs and record.holds(runs)
    return Layered(store, source, recorded, record.curves(name) if whole else None)


def runs_source(root: Path, name: str, universe: tuple[str, str] | None = None) -> Record | None:
    """Where the record at ``root`` holds runs of experiment ``name``: its files, and beside them, for a run of
    ``universe`` (a multiverse's name and one of its universes'), that universe's file (:class:`Beside`),
    each only where its files have the SHA-256 the manifest gives them (:func:`checked`); None where neither."""
    record = Record(root)
    sources = [record] if checked(root, name) is not None else []
    if universe and checked(root, universe[0]) is not None:
        sources.append(record.universe(*universe))
    return (sources[0] if len(sources) == 1 else Beside(root, tuple(sources))) if sources else None


class Beside(Record):
    """Records read one beside the other (an experiment's own files, then one universe's): a run's row is the
    first that has the run's key, or else the first there is (a stale one: :meth:`Record.stale`)."""

    def __init__(self, root: Path, sources: tuple[Record, ...]):
        super().__init__(root)
        self.sources = sources

    def found(self, runs: list[Run]) -> list[tuple[Run, dict]]:
        pairs = []
        for run in runs:
            rows = [row for source in self.sources for _, row in source.found([run])]
            if rows:
                pairs.append((run, next((row for row in rows if row["run_key"] == run.key), rows[0])))
        return pairs


def checked(root: Path, name: str) -> Entry | None:
    """The manifest's entry of ``name`` in the record at ``root`` where its files have the SHA-256 the manifest
    gives them; None where the record holds no ``name``, or a file of it is damaged (said in one line on
    stderr, once while the files stay as they are)."""
    if not (root / MANIFEST).exists():
        return None
    files = sorted(path for path in [root / MANIFEST, *(root / name).rglob("*")] if path.is_file())
    return _checked(root, name, tuple((str(path), path.stat().st_mtime_ns, path.stat().st_size) for path in files))


@lru_cache(maxsize=64)
def _checked(root: Path, name: str, stamp: tuple) -> Entry | None:
    entry = Manifest.read(root).experiments.get(name)
    damaged = entry.damaged(root) if entry else []
    if damaged:
        print(f"{name}: {root / damaged[0]} does not have the SHA-256 that {root / MANIFEST} gives it: nothing is read "
              "from the record, every run is computed (git checkout of the record restores it)", file=sys.stderr)
        return None
    return entry


def missing(cfg: DictConfig) -> str | None:
    """Where a paper-scale request would read the record and there is none (an installed copy), one line that
    says where one can be had; else None."""
    root = resolve(cfg.record)
    if not reads_record(cfg) or (root / MANIFEST).exists():
        return None
    return (f"no record at {root}, so every paper-scale run is computed here; a clone of the project ships one in "
            "record/: record=<its path> reads it (skip_recorded=false computes all, and says nothing)")


def said(name: str, layers: list[Layered], runs: int) -> str | None:
    """One line: how many of the ``runs`` distinct runs of ``name`` are read from the record beneath ``layers``
    (None: none)."""
    recorded = {(layer.directory, run_id) for layer in layers for run_id in layer.recorded}
    if not recorded:
        return None
    root = next(layer.record.root for layer in layers if layer.recorded)
    return (f"{name}: {len(recorded):,} of {runs:,} runs read from the record ({root}, SHA-256 checked), not "
            "computed (skip_recorded=false computes them)")


def recorded_universes(cfg: DictConfig, multiverse) -> dict[str, Record]:
    """The universes of ``multiverse`` (a :class:`~replication.runner.multiverse.Multiverse`) that the record
    holds whole as this code computes them, each as the record's view of it
    (:meth:`~replication.record.runs.Record.universes_held`); none unless ``skip_recorded`` and the paper scale,
    and none where the record's files of the multiverse are damaged (:func:`checked`).  A multiverse too long
    for one sitting then goes on, on any machine, where the record stops."""
    root = resolve(cfg.record)
    if not reads_record(cfg) or checked(root, multiverse.name) is None:
        return {}
    return Record(root).universes_held(multiverse)


def universes_beneath(cfg: DictConfig, multiverse) -> tuple[dict[str, Record], dict[tuple[str, str], Layered]]:
    """What a multiverse's runs are read from: the universes the record holds whole (:func:`recorded_universes`),
    and for each other universe and experiment, the store with the record beneath it, the experiment's files
    and the universe's (:func:`beneath`)."""
    recorded = recorded_universes(cfg, multiverse)
    return recorded, {(universe.name, name): beneath(cfg, multiverse.runs[universe.name, name],
                                                     Store(resolve(cfg.store), name), (multiverse.name, universe.name))
                      for universe in multiverse.universes if universe.name not in recorded
                      for name in multiverse.experiments}


def reader(recorded: dict[str, Record], layers: dict[tuple[str, str], Layered]):
    """``store_of(experiment, universe)`` for the multiverse's report, from :func:`universes_beneath`."""
    return lambda name, universe: recorded[universe.name] if universe.name in recorded else layers[universe.name, name]
