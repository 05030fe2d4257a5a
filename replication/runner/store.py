"""The result store: one JSON record per finished run, written atomically.

Layout: ``<root>/<experiment>/runs/<method>__<condition>__<key>__r<rep>.json``, or, for a run that
failed (:mod:`replication.runner.failures`), ``...__r<rep>.failed`` holding the reason.
The key hashes everything that can change a run's numbers (task, model and
method parameters, base seed, and the digest of the code the run executes,
:func:`replication.runner.provenance.run_code_digest`), so a changed config or filter lands in
new files and is never mixed with old runs, while adding repetitions, methods
or sweep values reuses every run already stored.

Damaged records.  Each record carries its own checksum (:data:`CHECKSUM`: the SHA-256 of the rest of the
record as canonical JSON, :func:`checksum`), written with it in the same file, so that the two are renamed
into place together and never disagree by a crash; the file stays one plain JSON object (no second file
per run to keep, copy or lose).  A record counts as stored only if it is a JSON object whose checksum
holds, with every key of :data:`REQUIRED_KEYS`, the identity of the run whose file it is in (same run id,
run key, method, condition, repetition, base seed), and each metric a number in its declared range
(:func:`replication.evidence.quantities.quantity`: a share in [0, 1], a count, an error or a time >= 0),
finite unless the metric is one that can be undefined (:data:`replication.runner.failures.UNDEFINED`).
Anything else -- a number edited by hand, a file truncated by a full disk or a copy, garbled bytes,
``"rmse": "abc"``, a record moved under another run's name -- is *corrupt*: :meth:`Store.pending`
renames it to ``<name>.json.corrupt`` (kept for inspection, ignored from then on) and hands the run back
to be computed again, and :meth:`Store.load` leaves it out of every table rather than aggregate it or
crash; both name it in one line (its path and what failed).  A record written before records carried a
checksum is *legacy*: read with its keys, identity, types and ranges checked, and said once (one line
with the count), never recomputed for that alone.  The checksum catches edits and damage, not forgery:
whoever edits a record and recomputes its checksum is believed.  Temporary files of a writer killed
mid-write (:data:`replication.atomic.TEMPORARIES`) are never read, and are deleted once an hour old.

Several processes or machines on one store (a shared or network file
system): every run is its own file, written to a new temporary file in the
same folder (a random name, created exclusively: no two writers share one) and
then renamed over its final name (:mod:`replication.atomic`: ``os.replace``, atomic on local POSIX file
systems and on NFS), readable by the group under the usual umask.  So

* no run is lost: writers never touch each other's files, and no file is
  ever rewritten in place, so a reader sees a whole record or none;
* no run is duplicated: a run has exactly one file name; if two writers
  compute the same run (both started before either finished), the second
  rename simply replaces the first file, and since a run is a pure function
  of its identity and seed both records agree in every column except the
  timings and the machine's load (``execute.TIMING_COLUMNS``) -- the last writer's
  are kept.  (That holds for machines with the same numpy, scipy
  and Python: the key covers this package's code only, and the records
  carry the library versions, machine and git commit to show where they came from.)
* work can be duplicated, not results: nothing locks a run while it is
  computed, so two machines started on the same experiment at once may both
  compute some runs.  Split the work (different experiments, methods or
  sweep values per machine) to avoid that, or use one cluster backend.

One race is benign by the same argument: a writer setting aside a file it
read as corrupt can, in the instant between reading and renaming, move aside
a good record another writer had just put there; the run is then computed
once more, to the same numbers.
"""

import hashlib
import json
import math
import sys
import time
from collections import Counter
from functools import lru_cache
from pathlib import Path

import pandas as pd

from replication.atomic import TEMPORARIES, DiskFull, write_text
from replication.errors import ConfigError
from replication.evidence.quantities import Quantity, quantity
from replication.run import Run
from replication.runner.failures import UNDEFINED

REQUIRED_KEYS = (  # written by execute.perform for every task
    "experiment", "method", "condition", "data_condition", "repetition", "run_key", "run_id",
    "base_seed", "replication_version", "wall_s",
)
CHECKSUM = "checksum"  # a record's own key: "sha256:" and the SHA-256 of the rest of it (:func:`checksum`)
CORRUPT_SUFFIX = ".corrupt"
STALE_TEMPORARY_S = 3600  # a temporary file this old belongs to a writer that was killed


class Store:
    def __init__(self, root: str | Path, experiment: str):
        self.directory = Path(root) / experiment / "runs"
        self.legacy: set[str] = set()  # the run ids of the records read without a checksum
        self._said_legacy = False

    def path(self, run: Run) -> Path:
        return self.directory / f"{_safe(run.run_id)}.json"

    def failure_path(self, run: Run) -> Path:
        return self.directory / f"{_safe(run.run_id)}.failed"

    def has(self, run: Run) -> bool:
        """Whether a sound record of ``run`` is stored (see :meth:`read`)."""
        try:
            return self.read(run) is not None
        except CorruptRecord:
            return False

    def read(self, run: Run) -> dict | None:
        """The stored record of ``run`` (without its checksum); None if there is none; :class:`CorruptRecord`
        if it is damaged or edited.  A record without a checksum is legacy (:attr:`legacy`)."""
        path = self.path(run)
        try:
            text = path.read_text()
        except FileNotFoundError:
            return None
        except (OSError, UnicodeDecodeError) as error:
            raise CorruptRecord(path, f"unreadable ({error.__class__.__name__})") from None
        try:
            record = json.loads(text)
        except ValueError:
            raise CorruptRecord(path, "invalid JSON" if text.strip() else "empty") from None
        if not isinstance(record, dict):
            raise CorruptRecord(path, f"a JSON {type(record).__name__}, not an object")
        claimed = record.pop(CHECKSUM, None)
        missing = [key for key in REQUIRED_KEYS if key not in record]
        if missing:
            raise CorruptRecord(path, f"missing {', '.join(missing)}")
        identity = run.identity()
        expected = {"run_id": identity.pop("run_id"), "run_key": identity.pop("run_key"), **identity,
                    "base_seed": run.base_seed}
        wrong = [key for key, value in expected.items() if record[key] != value]
        if wrong:
            found, wanted = _shown(record[wrong[0]]), expected[wrong[0]]
            raise CorruptRecord(path, f"{wrong[0]} {found} is not this file's {wanted!r}")
        wrong_value = next(filter(None, (unsound(key, value) for key, value in record.items())), None)
        if wrong_value:
            raise CorruptRecord(path, wrong_value)
        if claimed is not None and claimed != checksum(record):  # last: what is wrong is said where it can be
            raise CorruptRecord(path, "its checksum does not match its content: edited or damaged since written")
        if claimed is None:
            self.legacy.add(run.run_id)
        return record

    def pending(self, runs: list[Run]) -> tuple[list[Run], list[str]]:
        """The runs neither stored soundly nor failed, and one note per corrupt file set aside on the way.

        A corrupt file is renamed to ``<name>.json.corrupt`` so that its run is
        computed again and the damaged bytes stay for inspection.
        """
        self._remove_stale_temporaries()
        pending, notes = [], []
        for run in runs:
            try:
                if self.read(run) is not None or self.failure_path(run).exists():
                    continue
            except CorruptRecord as corrupt:
                notes.append(str(corrupt))
                try:
                    corrupt.path.replace(corrupt.path.with_name(corrupt.path.name + CORRUPT_SUFFIX))
                except FileNotFoundError:
                    pass  # another writer set it aside (or replaced it) in the meantime
            pending.append(run)
        self._say_legacy()
        return pending, notes

    def _remove_stale_temporaries(self) -> None:
        """Delete the temporaries of writers killed mid-write; a live writer's lives for milliseconds."""
        now = time.time()
        for tmp in self.directory.glob(TEMPORARIES):
            try:
                if now - tmp.stat().st_mtime > STALE_TEMPORARY_S:
                    tmp.unlink()
            except FileNotFoundError:
                pass

    def write(self, run: Run, record: dict) -> None:
        """Write ``record`` with its checksum, so that a crash leaves either the whole file or none of it."""
        record = json.loads(json.dumps(record))  # as a reader gets it back (lists, string keys): what it checks
        text = json.dumps({**record, CHECKSUM: checksum(record)}, indent=1, sort_keys=True)
        self._write(self.path(run), text)

    def write_failure(self, run: Run, reason: str) -> None:
        """Record that ``run`` failed, and why (see :mod:`replication.runner.failures`)."""
        self._write(self.failure_path(run), reason + "\n")

    def failures(self, runs: list[Run]) -> Counter[str]:
        """How many of ``runs`` failed, per reason; a run with a record as well counts as stored."""
        return Counter(
            self.failure_path(run).read_text().strip()
            for run in runs
            if self.failure_path(run).exists() and not self.path(run).exists()
        )

    def _write(self, path: Path, text: str) -> None:
        """``text`` as ``path``, whole or not at all, on the disk before it is renamed into place
        (:func:`replication.atomic.write_text`); a full disk is :class:`StoreFull`."""
        try:
            write_text(path, text, durable=True)
        except DiskFull:
            raise StoreFull(f"{self.directory}: no space left on its disk; every run stored before this one "
                            "is kept: free some space and rerun the same command to resume") from None

    def load(self, runs: list[Run]) -> pd.DataFrame:
        """The sound records of ``runs`` that are stored, one row per run, each with its run's condition
        variables as typed columns (``condition.N``, ``condition.scene``: :mod:`replication.condition`).

        Corrupt files are left out (never aggregated) and named in one line on
        stderr; running the experiment again sets them aside and recomputes them.
        """
        records, conditions, corrupt = [], [], []
        for run in runs:
            try:
                record = self.read(run)
            except CorruptRecord as error:
                corrupt.append(str(error))
                continue
            if record is not None:
                records.append(record)
                conditions.append(run.condition.columns())
        if corrupt:
            print(
                f"ignoring {len(corrupt)} corrupt result file(s) (rerun the experiment to recompute them): "
                + summarise(corrupt),
                file=sys.stderr,
            )
        self._say_legacy()
        table = pd.DataFrame.from_records(records)
        typed = pd.DataFrame(conditions, index=table.index, dtype=object)  # N stays an int beside a missing N
        return pd.concat([table, typed], axis=1) if len(typed.columns) else table

    def _say_legacy(self) -> None:
        """One line, once, on the legacy records read so far (none: nothing)."""
        if self.legacy and not self._said_legacy:
            self._said_legacy = True
            print(f"{len(self.legacy)} stored record(s) in {self.directory} were written before records "
                  "carried a checksum: read as legacy, their types and ranges checked", file=sys.stderr)


def checksum(record: dict) -> str:
    """``sha256:`` and the SHA-256 of ``record`` (without its checksum) as canonical JSON: keys sorted, no
    spaces, ASCII, floats as Python writes them (exactly, NaN as ``NaN``); the same values give the same
    checksum however the file is laid out."""
    canonical = json.dumps(record, sort_keys=True, separators=(",", ":"))
    return "sha256:" + hashlib.sha256(canonical.encode()).hexdigest()


def unsound(key: str, value) -> str | None:
    """What is wrong with a record's ``key``: ``value``, if it is a metric whose type or range does not hold
    (:func:`replication.evidence.quantities.quantity` declares each metric's range); None otherwise, and for
    keys that are not metrics."""
    declared = _declared(key)
    if declared is None:
        return None  # not a metric: identity, provenance, a per-frame series
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return f"{key} {_shown(value)} is not a number"
    if not math.isfinite(value):
        return None if key in UNDEFINED else f"{key} {value!r} is not finite (it is defined for every run)"
    if not declared.low <= value <= declared.high:
        return f"{key} {value!r} is outside its range [{declared.low:g}, {declared.high:g}]"
    return None


@lru_cache(maxsize=None)
def _declared(key: str) -> Quantity | None:
    """The quantity a record's ``key`` is, if it is a metric (a record has a few dozen keys, read again and
    again)."""
    try:
        return quantity(key)
    except ConfigError:
        return None


def _shown(value) -> str:
    found = repr(value)
    return found if len(found) <= 60 else found[:57] + "..."


class StoreFull(DiskFull):
    """The store's disk is full: one line saying which folder, and that what is stored is kept."""


class CorruptRecord(ValueError):
    """A stored file that is not a sound record of its run."""

    def __init__(self, path: Path, reason: str):
        super().__init__(f"{path} ({reason})")
        self.path, self.reason = path, reason


def summarise(notes: list[str], limit: int = 5) -> str:
    """``notes`` joined on one line, the first ``limit`` of them only."""
    shown = "; ".join(notes[:limit])
    return shown + (f"; and {len(notes) - limit} more" if len(notes) > limit else "")


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "=._-" else "_" for c in name)
