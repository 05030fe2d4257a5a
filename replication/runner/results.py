"""Tidy tables of an experiment's stored runs: a row per run (:func:`load_runs`) or frame (:func:`load_frames`).

``load_runs("ism_pf", scale="quick")`` expands the experiment as the runner does and reads the
records the store holds for it: a row per run, a column per metric and per parameter, swept or
fixed: ``method.<key>`` for the method's (``method.n_particles``), ``model.<key>`` for the model's
and its scene's, nested keys joined by dots (``model.scene_spec.frames``).  Per-frame series
(``per_frame``, a MOT run's ``tracks``: :func:`load_frames`; ``strip``, a marginal density per
frame, in the records only) stay out of it.

``load_frames("hspf", scale="quick")`` is the per-frame table of a tracking or MOT experiment,
a row per run and frame, with the run's identity (``experiment``, ``method``, ``condition``,
``repetition``, ``run_key``, ``scene``) and what its task's ``frame_table`` reads from the record
(:func:`replication.tasks.tracking.frame_table`: a row per target, its box and the frame's
errors; :func:`replication.tasks.mot.frame_table`: a row per track, its box).  Join the two on
``run_key`` for parameters.

    import seaborn as sns
    runs = load_runs("ism_pf", scale="quick")
    sns.pointplot(runs, x="method.n_particles", y="mean_cle", hue="method")
    frames = load_frames("hspf", scale="quick")
    sns.lineplot(frames, x="frame", y="cle", hue="method", units="run_key", estimator=None)

A report is drawn from one :class:`Results` (:meth:`Results.of`: the experiment's config at its scale,
its runs, their stored records and the failures' reasons), which also writes both tables
(:meth:`Results.write_tables`) as ``runs.parquet`` with ``runs.csv`` in the experiment's report folder, and
``frames.parquet`` (no CSV: up to a million rows at paper scale).
"""

import json
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd
from hydra import compose, initialize_config_dir
from omegaconf import DictConfig, OmegaConf

from replication import atomic
from replication.errors import ConfigError
from replication.paths import CONF_DIR, resolve
from replication.run import Run
from replication.runner.config import expand, experiment_at_scale
from replication.runner.multiverse import named_experiments
from replication.runner.store import Store
from replication.runner.variant import differences, report_name
from replication.tasks import TASKS

SERIES = ("per_frame", "strip", "tracks")  # per-frame data, kept in the records
FRAME_SERIES = ("per_frame", "tracks")  # what the tasks' frame_table read
IDENTITY = ("experiment", "method", "condition", "repetition", "run_key")


@dataclass(frozen=True)
class Results:
    """What a report is drawn from: the experiment's config as plain data at the scale run (real sequences
    located), its runs, their stored records (failed runs have none) and how many failed, per reason."""

    experiment: dict
    runs: list[Run]
    records: pd.DataFrame
    failures: Counter
    name: str  # the report's: the experiment's, or ``<experiment>@<label>`` for a user's own data or settings
    changes: tuple[str, ...] = ()  # what the request changed in the shipped experiment (runner.variant)
    command: str = ""  # the command line that made these results
    curves: dict[str, pd.DataFrame] = field(default_factory=dict)  # figure -> its curve table, where kept (record)
    at_paper_scale: dict = field(default_factory=dict)  # ``experiment`` at the paper's scale: what a scale changes

    @classmethod
    def of(cls, cfg: DictConfig, runs: list[Run], store: Store, overrides: tuple[str, ...] = (),
           curves: dict[str, pd.DataFrame] | None = None) -> "Results":
        """The stored results of ``runs``; ``overrides``: the request's command-line settings (for the page);
        ``curves``: the curve figures' tables where the runs' series are not at hand (the record's)."""
        changes = differences(cfg)
        command = " ".join(["python -m replication", f"experiment={cfg.experiment.name}", f"scale={cfg.scale}",
                            *(o for o in overrides if not o.startswith(("experiment=", "scale=")))])
        experiment = experiment_at_scale(cfg)
        return cls(experiment, runs, store.load(runs), store.failures(runs), report_name(cfg, changes),
                   tuple(changes), command, curves or {}, experiment_at_scale(cfg, "paper") if cfg.scale != "paper"
                   else experiment)

    @property
    def own(self) -> bool:
        """Whether these are a user's runs (own data, methods or settings): they judge no paper claim."""
        return bool(self.changes)

    def write_tables(self, out: Path) -> list[str]:
        """The runs (and, for a task with per-frame data, the frames) as tidy tables in ``out``; their
        file names."""
        if self.records.empty:
            return []
        write(tidy(self.records, self.runs), out / "runs")
        per_frame = frames(self.records, self.runs)
        if per_frame.empty:
            return ["runs.parquet", "runs.csv"]
        write(per_frame, out / "frames", csv=False)  # no CSV: up to 10^5 rows at quick scale, 10^6 at paper
        return ["runs.parquet", "runs.csv", "frames.parquet"]


def parameters(runs: list[Run]) -> pd.DataFrame:
    """The runs' parameters, a row per run keyed by ``run_key``, as flat columns ``method.<key>`` and
    ``model.<key>`` (nested keys joined by dots)."""
    flat = pd.json_normalize([{"method": run.method_params, "model": run.model} for run in runs], sep=".")
    return flat.assign(run_key=[run.key for run in runs])[["run_key", *flat]]


def tidy(records: pd.DataFrame, runs: list[Run]) -> pd.DataFrame:
    """The ``records`` of ``runs`` (:meth:`Store.load`) without their series, with a column per parameter:
    the run's identity first, then its parameters, then its metrics and provenance."""
    if records.empty:
        return records
    table = parameters(runs).drop_duplicates("run_key")
    records = records.drop(columns=[c for c in SERIES if c in records])
    by_part = sorted(table, key=lambda column: column.split(".")[0])  # method.* before model.*
    columns = dict.fromkeys([*IDENTITY, "run_id", *by_part, *records])  # in that order, each once
    return records.merge(table, on="run_key", how="left", validate="many_to_one")[list(columns)]


def frames(records: pd.DataFrame, runs: list[Run]) -> pd.DataFrame:
    """The per-frame rows of the ``records`` of ``runs``, each with its run's identity; empty for a
    task without per-frame data (``scalar``), and for records without their series (the paper-scale
    record's, :mod:`replication.record`)."""
    if not any(series in records for series in FRAME_SERIES):
        return pd.DataFrame()
    by_id = {run.run_id: run for run in runs}
    tables = []
    for record in records.to_dict("records"):
        run = by_id[record["run_id"]]
        if hasattr(TASKS[run.task], "frame_table"):
            table = TASKS[run.task].frame_table(record)
            identity = {**{key: record[key] for key in IDENTITY}, "scene": run.model["scene"]}
            tables.append(table.assign(**identity)[[*identity, *table.columns]])
    return pd.concat(tables, ignore_index=True) if tables else pd.DataFrame()


def write(table: pd.DataFrame, path: Path, csv: bool = True) -> None:
    """``table`` as ``<path>.parquet`` and, with ``csv``, ``<path>.csv``: the same table in both.

    A list or mapping (``method.max_velocity``, ``model.scene_spec.targets``) is written as its JSON
    text: a CSV cell holds no list, and a Parquet column cannot hold both a list and a word (a
    scene's ``track``: ``[0, 2]`` or ``all``).
    """
    nested = [c for c in table if table[c].dtype == object and table[c].map(_nested).any()]
    table = table.assign(**{c: table[c].map(lambda v: json.dumps(v) if _nested(v) else v) for c in nested})
    atomic.save(path.with_suffix(".parquet"), lambda tmp: table.to_parquet(tmp, index=False))
    if csv:
        atomic.save(path.with_suffix(".csv"), lambda tmp: table.to_csv(tmp, index=False))


def load_runs(experiment: str, scale: str | None = None, *overrides: str) -> pd.DataFrame:
    """Every stored run of ``experiment`` at ``scale`` (None: ``conf/config.yaml``'s, quick), one row each, with
    its parameters and metrics.

    ``overrides`` are the command line's (``"store=/path"``, ``"experiment.runs.quick=3"``); runs not
    yet stored are absent (run the experiment first), and so are runs that failed
    (:mod:`replication.runner.failures`).
    """
    return tidy(*stored_records(experiment, scale, *overrides))


def load_frames(experiment: str, scale: str | None = None, *overrides: str) -> pd.DataFrame:
    """Every frame of every stored run of ``experiment`` at ``scale`` (:func:`frames`); arguments as
    :func:`load_runs`."""
    return frames(*stored_records(experiment, scale, *overrides))


def stored_records(experiment: str, scale: str | None = None, *overrides: str) -> tuple[pd.DataFrame, list[Run]]:
    """The stored records of an experiment's runs, and the runs (a multiverse has none of its own: its
    experiments' runs are theirs, and it says so)."""
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        cfg = compose("config", overrides=[f"experiment={experiment}", *([f"scale={scale}"] if scale else []),
                                           *overrides])
    if "multiverse" in cfg.experiment:
        named = named_experiments(OmegaConf.to_container(cfg.experiment.multiverse, resolve=True))
        raise ConfigError(f"{experiment} is a multiverse: its runs are stored under its experiments', "
                          f"name one of them: {', '.join(named)}")
    runs = expand(cfg)
    return Store(resolve(cfg.store), cfg.experiment.name).load(runs), runs


def _nested(value) -> bool:
    return isinstance(value, (list, dict))
