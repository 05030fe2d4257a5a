"""Fan runs out with joblib and store each record the moment it arrives.

Where the runs go is ``parallel.backend`` (see ``conf/config.yaml``), one of
:data:`~replication.runner.backends.BACKENDS`: worker processes on this machine or a dask or ray
cluster (a backend that cannot stream, ray's, sends its records back a batch at a time).  Wherever a run is computed, its
record is a pure function of its identity and seed, so every backend stores
the same numbers; only the records are sent back, and only this process
writes the store.  Cluster workers need this package (and the same numpy,
scipy and numba) installed; tracking runs also need the scene data at the
same relative path.
"""

import sys
import warnings
from collections.abc import Iterator
from contextlib import closing

import numpy as np
from joblib import Parallel, delayed, effective_n_jobs
from tqdm.auto import tqdm

import replication
from replication.condition import Condition
from replication.errors import RunFailed
from replication.run import Run
from replication.runner.backends import BACKENDS, WorkerLost, one_line, parallel_backend
from replication.runner.bounds import MANY_RUNS
from replication.runner.failures import failure
from replication.runner.memory import one_thread, retain_freed_memory
from replication.runner.provenance import provenance
from replication.runner.store import Store, summarise
from replication.stopwatch import Stopwatch, load_1m, machine_speed
from replication.tasks import TASKS

# machine- and moment-dependent: left out of determinism checks
TIMING_COLUMNS = ("wall_s", "cpu_s", "ms_per_step", "cpu_ms_per_step", "ms_per_frame", "cpu_ms_per_frame", "filter_s",
                  "cpu_filter_s", "fps", "load_1m", "reference_ms", "computed_at")
RUNS_PER_WORKER = 2  # a backend that cannot stream sends its records back this many runs per worker at a time


def perform(run: Run) -> dict:
    """One run: a pure function of the run's identity, parameters and seed.  Its record, or, when a
    number it needs or gives is not finite or its method returns the wrong thing, only its run id and the
    reason (``failure``, :mod:`.failures`).

    A run during which numba compiled a kernel (the first use of a kernel, or of a new type signature, in
    a fresh checkout whose compiled cache is empty: seconds each) is computed again and that second
    record kept: the same numbers, and times that are the method's own, not the compiler's."""
    from numba.core import event  # here: the command line checks a request before anything heavy is imported

    retain_freed_memory()  # in whichever process computes it: a worker of any backend
    one_thread()
    with event.install_recorder("numba:compile") as compiled:
        record = _performed(run)
    return _performed(run) if compiled.buffer and "failure" not in record else record


def _performed(run: Run) -> dict:
    with Stopwatch() as stopwatch:
        try:
            metrics = TASKS[run.task].run(run)
            reason = failure(metrics)
        except RunFailed as error:
            reason = str(error)
    if reason:
        return {"run_id": run.run_id, "failure": reason}
    return {
        **run.identity(),
        **metrics,
        "wall_s": stopwatch.wall,
        "cpu_s": stopwatch.cpu,  # this thread's: the run's own work, whatever else the machine did
        "load_1m": load_1m(),  # the machine's, as the run ended: above its cores, runs waited for one
        "reference_ms": machine_speed(),  # the machine's speed about then: a fixed work's time on this worker
        "base_seed": run.base_seed,
        "replication_version": replication.__version__,
        **provenance(),
    }


def _records(pending: list[Run], streamed: bool) -> Iterator[dict]:
    """Each run's record as it finishes, from the joblib backend in force.

    Where the backend cannot stream, batches of a few runs per worker: an
    interruption then loses at most one batch, and a batch waits for its
    slowest run before the next starts.
    """
    if streamed:
        results = Parallel(return_as="generator_unordered")(delayed(perform)(run) for run in pending)
        try:
            for record in results:  # not "yield from": closing this generator must close results in here
                yield record
        finally:
            with warnings.catch_warnings():  # joblib warns that the generator was left unfinished: we know
                warnings.simplefilter("ignore")
                results.close()  # if interrupted between two records: stop the workers now
        return
    batch = RUNS_PER_WORKER * effective_n_jobs(None)  # the n_jobs in force (a ray cluster: its CPUs)
    with Parallel() as parallel:  # one pool for every batch
        for start in range(0, len(pending), batch):
            yield from parallel(delayed(perform)(run) for run in pending[start : start + batch])


def forecast(runs: list[Run], pending: list[Run], store: Store, n_jobs: int, sample: int = 5) -> str:
    """What a request is about to do, before it does it: how many runs, how many to compute, and roughly how
    long, from the wall times of up to ``sample`` stored runs of each method and condition (of the same
    experiment; their mean over all stored runs where a condition has none) over the workers."""
    said = f"{runs[0].experiment}: {len(runs):,} runs, {len(pending):,} to compute"
    waiting = {run.run_id for run in pending}
    seen: dict[tuple[str, Condition], list[float]] = {}
    for run in runs:
        times = seen.setdefault((run.method, run.condition), [])
        if len(times) < sample and run.run_id not in waiting:
            record = store.read(run)
            if record is not None:
                times.append(float(record["wall_s"]))
    known = [t for times in seen.values() for t in times]
    if not known:
        return f"{said} (no stored run of it to time them by)"
    workers = min(effective_n_jobs(n_jobs) if n_jobs else 1, len(pending))
    each = {condition: np.mean(times or known) for condition, times in seen.items()}  # once, not once a run
    seconds = sum(each[run.method, run.condition] for run in pending) / max(workers, 1)
    return f"{said}, about {duration(seconds)} on {workers} worker(s) (from {len(known)} stored runs' times)"


def duration(seconds: float) -> str:
    """A rough duration in the unit a reader wants: seconds, minutes or hours."""
    return f"{seconds:.0f} s" if seconds < 120 else f"{seconds / 60:.0f} min" if seconds < 7200 else f"{seconds / 3600:.1f} h"


def schedule(runs: list[Run]) -> list[Run]:
    """The order runs start in: data condition by data condition (a scene, in the order they come), and in
    each, repetition by repetition, every method and particle count of one repetition together.  So the runs
    that will be compared (paired on the same data and repetition) are computed close in time, and each
    method's and N's runs spread over the whole span of their scene: a change of the machine's load while
    an experiment runs falls on every condition alike, not on the conditions that happen to run then (a
    time per step compared across an N sweep, the equal-time readings); and one repetition's video, drawn
    once per run when each repetition has its own, serves its methods from the scene cache.  The order
    changes no record: each run's numbers depend only on its own seed."""
    scenes = {data: i for i, data in enumerate(dict.fromkeys(str(run.data_condition) for run in runs))}
    return sorted(runs, key=lambda run: (scenes[str(run.data_condition)], run.repetition))


def execute(
    runs: list[Run],
    store: Store,
    n_jobs: int = 2,
    backend: str = "loky",
    progress: bool = True,
    address: str | None = None,
) -> int:
    """Run every run neither stored nor failed; return how many were run.

    Records (or the failures of runs with numbers that are not finite) are written by this process as
    each run finishes (in any order), so an interrupted job loses only the runs in flight, and a rerun
    of the same command skips everything already stored or failed.  Corrupt result files are
    named in one line on stderr, set aside and run again (see :mod:`.store`).
    A KeyboardInterrupt stops the workers and propagates, with every record
    that arrived before it stored.
    """
    if not runs:  # every run read from the record, say
        return 0
    checked = tqdm(runs, desc=f"{runs[0].experiment}: checking the store", unit="run", mininterval=1.0,
                   disable=not progress or len(runs) < MANY_RUNS)
    pending, corrupt = store.pending(checked)
    pending = schedule(pending)
    if corrupt:
        print(f"re-running {len(corrupt)} corrupt result file(s): {summarise(corrupt)}", file=sys.stderr)
    if not pending:
        return 0
    if progress:
        print(forecast(runs, pending, store, n_jobs), flush=True)
    by_id, stored = {run.run_id: run for run in pending}, 0
    bar = tqdm(
        total=len(runs),
        initial=len(runs) - len(pending),
        desc=runs[0].experiment,
        unit="run",
        disable=not progress,
        mininterval=1.0,
    )
    lost = BACKENDS[backend].lost()
    try:
        with bar, parallel_backend(backend, n_jobs, address), closing(
            _records(pending, streamed=BACKENDS[backend].streams)
        ) as records:
            for record in records:
                run = by_id[record["run_id"]]
                if "failure" in record:
                    store.write_failure(run, record["failure"])
                else:
                    store.write(run, record)
                stored += 1
                bar.update()
    except lost as error:
        raise WorkerLost(f"{runs[0].experiment}: a worker process ended in mid-run and the {backend} backend gave "
                         f"up on its runs ({error.__class__.__name__}: {one_line(error)}); the {stored} runs "
                         "finished before it are stored: rerun the same command to compute the rest") from None
    return len(pending)
