"""Fan runs out with joblib and store each record the moment it arrives."""

import platform
import time

import numpy as np
from joblib import Parallel, delayed, parallel_config
from tqdm.auto import tqdm

import replication
from replication.runner.config import Run
from replication.runner.store import Store
from replication.tasks import TASKS

TIMING_COLUMNS = ("wall_s", "ms_per_step", "ms_per_frame", "filter_s", "fps")  # machine-dependent: left out of determinism checks


def perform(run: Run) -> dict:
    """One run: a pure function of the run's identity, parameters and seed."""
    started = time.perf_counter()
    metrics = TASKS[run.task].run(run)
    return {
        **run.identity(),
        **metrics,
        "wall_s": time.perf_counter() - started,
        "base_seed": run.base_seed,
        "replication_version": replication.__version__,
        "numpy_version": np.__version__,
        "python_version": platform.python_version(),
    }


def execute(runs: list[Run], store: Store, n_jobs: int = 2, backend: str = "loky", progress: bool = True) -> int:
    """Run every run not yet stored; return how many were run.

    Records are written by this process as each run finishes (in any order),
    so an interrupted job loses only the runs in flight, and a rerun of the
    same command skips everything already stored.
    """
    pending = [run for run in runs if not store.has(run)]
    if not pending:
        return 0
    by_id = {run.run_id: run for run in pending}
    bar = tqdm(
        total=len(runs),
        initial=len(runs) - len(pending),
        desc=runs[0].experiment,
        unit="run",
        disable=not progress,
        mininterval=1.0,
    )
    with bar, parallel_config(backend=backend, n_jobs=n_jobs):
        results = Parallel(return_as="generator_unordered")(delayed(perform)(run) for run in pending)
        for record in results:
            store.write(by_id[record["run_id"]], record)
            bar.update()
    return len(pending)

