"""An experiment's runs as one tidy, typed table (:func:`runs_table`), and the record read back as a store
(:class:`Record`).

A row is a run, matched to the runs an experiment expands to by its identity (:func:`identity`: method,
repetition and condition values, never a label parsed back), so a record made by other code is still
read, and said to be (:meth:`Record.stale`).  Columns are typed: Parquet's integers, floats, strings,
booleans, lists and structs; a column whose values have no one type (a scene's ``track``: ``[0, 2]`` or
``all``) is stored as JSON text and named in the file's metadata (``json_columns``), so it reads back as
it was stored.
"""

import json
import math
from collections import Counter
from functools import lru_cache
from pathlib import Path

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from replication import atomic
from replication.condition import PREFIX
from replication.run import Run
from replication.runner.results import SERIES, parameters

RUNS_FILE = "runs.parquet"
CURVES_DIR = "curves"  # <experiment>/curves/<figure>.parquet: what a curve figure draws (runner.curves)
UNIVERSES_DIR = "universes"  # <multiverse>/universes/<universe>.parquet: a universe's runs of each experiment
JSON_COLUMNS = b"json_columns"
FAILURE = "failure"  # a failed run's reason (None for a run with a record)
LABELS = ("condition", "data_condition", "run_id")  # derived from the identity: not stored
PARAMETERS = ("method.", "model.")  # a run's parameters (for readers of the table; the key covers them)
UNIVERSE = "universe."  # a multiverse's row: the alternative its universe picks for each choice (universe.sigma)


def identity(method: str, repetition: int, conditions: dict) -> tuple:
    """What names a run across code changes: its method, repetition and condition values."""
    values = tuple(sorted((name, value) for name, value in conditions.items() if not _missing(value)))
    return method, int(repetition), values


def run_identity(run: Run) -> tuple:
    return identity(run.method, run.repetition, run.condition.columns())


def row_identity(row: dict) -> tuple:
    return identity(row["method"], row["repetition"], {k: v for k, v in row.items() if k.startswith(PREFIX)})


def row(run: Run, record: dict | None, failure: str | None, series: tuple[str, ...]) -> dict:
    """``run``'s row: identity, condition values, parameters, then the record's metrics and provenance (its
    per-frame ``series`` kept, the others left out), or its ``failure``."""
    head = {"experiment": run.experiment, "method": run.method, "repetition": run.repetition,
            "run_key": run.key, "base_seed": run.base_seed, **run.condition.columns()}
    head.update({k: v for k, v in parameters([run]).iloc[0].items() if k.startswith(PARAMETERS)})
    if record is None:
        return {**head, FAILURE: failure}
    kept = {k: v for k, v in record.items() if k not in head and k not in LABELS and (k not in SERIES or k in series)}
    return {**head, **kept, FAILURE: None}


def runs_table(rows: list[dict]) -> pa.Table:
    """The rows as one Arrow table, a column per key (in first-seen order), typed by Arrow where the values
    share a type and JSON text where they do not."""
    names = list(dict.fromkeys(name for r in rows for name in r))
    columns, as_json = {}, []
    for name in names:
        values = [r.get(name) for r in rows]
        try:
            columns[name] = pa.array(values)
        except (pa.ArrowInvalid, pa.ArrowTypeError, pa.ArrowNotImplementedError):
            columns[name] = pa.array([None if v is None else json.dumps(v) for v in values], pa.string())
            as_json.append(name)
    table = pa.table(columns)
    return table.replace_schema_metadata({JSON_COLUMNS: json.dumps(as_json).encode()})


def write_table(table: pa.Table, path: Path) -> None:
    """``table`` as Parquet, zstd-compressed; the same table gives the same bytes."""
    atomic.save(path, lambda tmp: pq.write_table(table, tmp, compression="zstd", compression_level=9))


def read_rows(path: Path) -> list[dict]:
    """A runs table's rows as plain Python values (lists, dicts, ints), as its runs' records held them (a
    value a record lacked is None, as a table of records makes it)."""
    table = pq.read_table(path)
    as_json = set(json.loads((table.schema.metadata or {}).get(JSON_COLUMNS, b"[]")))
    return [{k: json.loads(v) if k in as_json and v is not None else v for k, v in r.items()}
            for r in table.to_pylist()]


class Record:
    """A record folder read as a store: :meth:`load` and :meth:`failures` answer as
    :class:`~replication.runner.store.Store`'s do, from the record's rows.  :meth:`universe` is the view of
    one universe of a recorded multiverse (its own file: its runs share their identities with every other
    universe's)."""

    def __init__(self, root: str | Path, universe_file: Path | None = None):
        self.root, self.universe_file = Path(root), universe_file

    def universe(self, multiverse: str, universe: str) -> "Record":
        """The recorded runs of the universe named ``universe`` of ``multiverse`` (none if it is not recorded)."""
        return Record(self.root, universe_path(self.root, multiverse, universe))

    def found(self, runs: list[Run]) -> list[tuple[Run, dict]]:
        """Each of ``runs`` the record holds, with its row."""
        pairs = []
        for run in runs:
            found = _rows(self.universe_file or self.root / run.experiment / RUNS_FILE).get(
                (run.experiment, run_identity(run)))
            if found is not None:
                pairs.append((run, found))
        return pairs

    def load(self, runs: list[Run]) -> pd.DataFrame:
        """The recorded runs among ``runs`` as :meth:`Store.load` gives stored ones: one row per run with a
        record, its identity from the run (its ``run_key`` the recorded one) and its condition columns."""
        records, conditions = [], []
        for run, found in self.found(runs):
            if found.get(FAILURE) is None:  # a run with a record
                kept = {k: v for k, v in found.items()
                        if not k.startswith((PREFIX, UNIVERSE, *PARAMETERS)) and k != FAILURE}
                records.append({**kept, **run.identity(), "run_key": found["run_key"]})
                conditions.append(run.condition.columns())
        table = pd.DataFrame.from_records(records)
        typed = pd.DataFrame(conditions, index=table.index, dtype=object)
        return pd.concat([table, typed], axis=1) if len(typed.columns) else table

    def failures(self, runs: list[Run]) -> Counter:
        """How many of ``runs`` the record holds as failed, per reason."""
        return Counter(found[FAILURE] for _, found in self.found(runs) if found.get(FAILURE))

    def curves(self, experiment: str) -> dict[str, pd.DataFrame]:
        """The tables the experiment's curve figures draw, by figure name."""
        return {path.stem: pq.read_table(path).to_pandas()
                for path in sorted((self.root / experiment / CURVES_DIR).glob("*.parquet"))}

    def holds(self, runs: list[Run]) -> bool:
        """Whether every one of ``runs`` is recorded, and as this code and these settings compute it (its
        recorded key is the run's): reading it here gives what running it would."""
        found = self.found(runs)
        return len(found) == len(runs) and all(row["run_key"] == run.key for run, row in found)

    def seconds(self, runs: list[Run]) -> dict[tuple[str, str, str], float]:
        """The mean recorded wall time of ``runs`` by experiment, method and condition (those recorded with
        a time)."""
        times: dict[tuple[str, str, str], list[float]] = {}
        for run, found in self.found(runs):
            if found.get("wall_s") is not None:
                times.setdefault((run.experiment, run.method, str(run.condition)), []).append(found["wall_s"])
        return {key: sum(values) / len(values) for key, values in times.items()}

    def universes_held(self, multiverse) -> dict[str, "Record"]:
        """The universes of ``multiverse`` (a :class:`~replication.runner.multiverse.Multiverse`) whose every run
        this record holds as this code computes it (:meth:`holds`), each as its view (:meth:`universe`)."""
        views = {u.name: self.universe(multiverse.name, u.name) for u in multiverse.universes}
        return {name: view for name, view in views.items()
                if all(view.holds(multiverse.runs[name, e]) for e in multiverse.experiments)}

    def stale(self, runs: list[Run]) -> list[Run]:
        """The recorded runs among ``runs`` that other code or settings made (their recorded key is not
        the run's): the record shows what that code computed, not what this code would."""
        return [run for run, found in self.found(runs) if found["run_key"] != run.key]

    def stale_universes(self, multiverse) -> int:
        """How many of ``multiverse``'s recorded runs, over all its universes, other code or settings made
        (:meth:`stale`)."""
        return sum(len(self.universe(multiverse.name, u.name).stale(multiverse.runs[u.name, e]))
                   for u in multiverse.universes for e in multiverse.experiments)


def universe_path(root: Path, multiverse: str, universe: str) -> Path:
    """``<root>/<multiverse>/universes/<universe>.parquet``, the universe's name made a file name
    (``sigma=s005; noise_on=x`` -> ``sigma=s005__noise_on=x``)."""
    return Path(root) / multiverse / UNIVERSES_DIR / f"{universe.replace('; ', '__')}.parquet"


@lru_cache(maxsize=64)
def _rows_cached(path: Path, stamp: tuple) -> dict[tuple, dict]:
    return {(r["experiment"], row_identity(r)): r for r in read_rows(path)}


def _rows(path: Path) -> dict[tuple, dict]:
    if not path.exists():
        return {}
    stat = path.stat()
    return _rows_cached(path, (stat.st_mtime_ns, stat.st_size))


def _missing(value) -> bool:
    return value is None or (isinstance(value, float) and math.isnan(value))
