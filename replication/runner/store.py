"""The result store: one JSON record per finished run, written atomically.

Layout: ``<root>/<experiment>/runs/<method>__<condition>__<key>__r<rep>.json``, or, for a run that
failed (:mod:`replication.runner.failures`), ``...__r<rep>.failed`` holding the reason.
The key hashes everything that can change a run's numbers (task, model and
method parameters, base seed, and the digest of the code the run executes,
:func:`replication.runner.provenance.run_code_digest`), so a changed config or filter lands in
new files and is never mixed with old runs, while adding repetitions, methods
or sweep values reuses every run already stored.

Damaged records.  A record counts as stored only if it is a JSON object with
every key of :data:`REQUIRED_KEYS` and the identity of the run whose file it is
in (same run id, run key, method, condition, repetition, base seed).  Anything
else -- a file truncated by a full disk or a copy, garbled bytes, a record
moved under another run's name -- is *corrupt*: :meth:`Store.pending` renames
it to ``<name>.json.corrupt`` (kept for inspection, ignored from then on) and
hands the run back to be computed again, and :meth:`Store.load` leaves it out
of every table rather than aggregate it or crash.  Temporary files of a writer
killed mid-write (``.<random>.tmp``) are never read, and are deleted once an
hour old.

Several processes or machines on one store (a shared or network file
system): every run is its own file, written to a new temporary file in the
same folder (a random name, created exclusively: no two writers share one) and
then renamed over its final name (``os.replace``, atomic on local POSIX file
systems and on NFS), readable by the group under the usual umask.  So

* no run is lost: writers never touch each other's files, and no file is
  ever rewritten in place, so a reader sees a whole record or none;
* no run is duplicated: a run has exactly one file name; if two writers
  compute the same run (both started before either finished), the second
  rename simply replaces the first file, and since a run is a pure function
  of its identity and seed both records agree in every column except the
  wall-clock timings (``execute.TIMING_COLUMNS``) -- the last writer's
  timings are kept.  (That holds for machines with the same numpy, scipy
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

import errno
import json
import os
import secrets
import sys
import time
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import TextIO

import pandas as pd

from replication.run import Run

REQUIRED_KEYS = (  # written by execute.perform for every task
    "experiment", "method", "condition", "data_condition", "repetition", "run_key", "run_id",
    "base_seed", "replication_version", "wall_s",
)
CORRUPT_SUFFIX = ".corrupt"
STALE_TEMPORARY_S = 3600  # a temporary file this old belongs to a writer that was killed


class Store:
    def __init__(self, root: str | Path, experiment: str):
        self.directory = Path(root) / experiment / "runs"

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
        """The stored record of ``run``; None if there is none; :class:`CorruptRecord` if it is damaged."""
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
        missing = [key for key in REQUIRED_KEYS if key not in record]
        if missing:
            raise CorruptRecord(path, f"missing {', '.join(missing)}")
        identity = run.identity()
        expected = {"run_id": identity.pop("run_id"), "run_key": identity.pop("run_key"), **identity,
                    "base_seed": run.base_seed}
        wrong = [key for key, value in expected.items() if record[key] != value]
        if wrong:
            found = repr(record[wrong[0]])
            found = found if len(found) <= 60 else found[:57] + "..."
            raise CorruptRecord(path, f"{wrong[0]} {found} is not this file's {expected[wrong[0]]!r}")
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
        return pending, notes

    def _remove_stale_temporaries(self) -> None:
        """Delete the temporaries of writers killed mid-write; a live writer's lives for milliseconds."""
        now = time.time()
        for tmp in self.directory.glob(".*.tmp"):
            try:
                if now - tmp.stat().st_mtime > STALE_TEMPORARY_S:
                    tmp.unlink()
            except FileNotFoundError:
                pass

    def write(self, run: Run, record: dict) -> None:
        """Write ``record`` so that a crash leaves either the whole file or none of it."""
        self._write(self.path(run), lambda handle: json.dump(record, handle, indent=1, sort_keys=True))

    def write_failure(self, run: Run, reason: str) -> None:
        """Record that ``run`` failed, and why (see :mod:`replication.runner.failures`)."""
        self._write(self.failure_path(run), lambda handle: handle.write(reason + "\n"))

    def failures(self, runs: list[Run]) -> Counter[str]:
        """How many of ``runs`` failed, per reason; a run with a record as well counts as stored."""
        return Counter(
            self.failure_path(run).read_text().strip()
            for run in runs
            if self.failure_path(run).exists() and not self.path(run).exists()
        )

    def _write(self, path: Path, fill: Callable[[TextIO], object]) -> None:
        """Write a new temporary file in the same folder with ``fill(handle)``, then rename it to ``path``.
        The file gets the mode ``open()`` gives (0o666 less the umask: readable by the group and others
        under the usual umask 022), so that a store can be shared."""
        tmp = self.directory / f".{secrets.token_hex(8)}.tmp"
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
            with open(tmp, "x") as handle:  # "x": created here, never an existing file
                fill(handle)
                handle.flush()
                os.fsync(handle.fileno())
            os.replace(tmp, path)
        except BaseException as error:
            tmp.unlink(missing_ok=True)
            if isinstance(error, OSError) and error.errno in (errno.ENOSPC, errno.EDQUOT):
                raise StoreFull(f"{self.directory}: no space left on its disk; every run stored before this one is "
                                "kept: free some space and rerun the same command to resume") from None
            raise

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
        table = pd.DataFrame.from_records(records)
        typed = pd.DataFrame(conditions, index=table.index, dtype=object)  # N stays an int beside a missing N
        return pd.concat([table, typed], axis=1) if len(typed.columns) else table


class StoreFull(OSError):
    """The store's disk is full: one line saying which folder, and that what is stored is kept."""


class CorruptRecord(ValueError):
    """A stored file that is not a sound record of its run."""

    def __init__(self, path: Path, reason: str):
        super().__init__(f"{path.name} ({reason})")
        self.path, self.reason = path, reason


def summarise(notes: list[str], limit: int = 5) -> str:
    """``notes`` joined on one line, the first ``limit`` of them only."""
    shown = "; ".join(notes[:limit])
    return shown + (f"; and {len(notes) - limit} more" if len(notes) > limit else "")


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "=._-" else "_" for c in name)
