"""The result store: one JSON record per finished run, written atomically.

Layout: ``<root>/<experiment>/runs/<method>__<condition>__<key>__r<rep>.json``.
The key hashes everything that can change a run's numbers (task, model and
method parameters, base seed, package version), so a changed config lands in
new files and is never mixed with old runs, while adding repetitions, methods
or sweep values reuses every run already stored.
"""

import json
import os
import tempfile
from pathlib import Path

import pandas as pd

from replication.runner.config import Run


class Store:
    def __init__(self, root: str | Path, experiment: str):
        self.directory = Path(root) / experiment / "runs"

    def path(self, run: Run) -> Path:
        return self.directory / f"{_safe(run.run_id)}.json"

    def has(self, run: Run) -> bool:
        return self.path(run).exists()

    def write(self, run: Run, record: dict) -> None:
        """Write ``record`` so that a crash leaves either the whole file or none of it."""
        self.directory.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=self.directory, prefix=".", suffix=".tmp")
        try:
            with os.fdopen(fd, "w") as handle:
                json.dump(record, handle, indent=1, sort_keys=True)
                handle.flush()
                os.fsync(handle.fileno())
            os.replace(tmp, self.path(run))
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise

    def load(self, runs: list[Run]) -> pd.DataFrame:
        """The records of ``runs`` that are stored, one row per run."""
        records = []
        for run in runs:
            path = self.path(run)
            if path.exists():
                records.append(json.loads(path.read_text()))
        return pd.DataFrame.from_records(records)


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "=._-" else "_" for c in name)
