"""Fan runs out with joblib and store each record the moment it arrives.

Where the runs go is ``parallel.backend`` (see ``conf/config.yaml``): ``loky``
worker processes on this machine (the default), ``threading``, or a cluster:
``dask`` (a ``distributed`` scheduler at ``parallel.address``, or a local
cluster of ``n_jobs`` worker processes on the loopback when no address is given) or ``ray``
(``ray.init(address=parallel.address)``, an address first checked to answer; no address: a new
local cluster, never a stale one a past run left named in ray's files; ray's joblib backend cannot
stream results, so its records come back and are stored a batch at a time).  Wherever a run is computed, its
record is a pure function of its identity and seed, so every backend stores
the same numbers; only the records are sent back, and only this process
writes the store.  Cluster workers need this package (and the same numpy,
scipy and numba) installed; tracking runs also need the scene data at the
same relative path.
"""

import asyncio
import importlib.util
import ipaddress
import logging
import os
import signal
import socket
import sys
import threading
import warnings
from collections.abc import Iterator
from contextlib import closing, contextmanager, nullcontext

import numpy as np
from joblib import Parallel, delayed, effective_n_jobs, parallel_config, register_parallel_backend
from tqdm.auto import tqdm

import replication
from replication.condition import Condition
from replication.errors import RunFailed
from replication.run import Run
from replication.runner.bounds import MANY_RUNS
from replication.runner.failures import failure
from replication.runner.lifeline import start_worker
from replication.runner.memory import one_thread, retain_freed_memory
from replication.runner.provenance import provenance
from replication.runner.store import Store, summarise
from replication.stopwatch import Stopwatch, load_1m, machine_speed
from replication.tasks import TASKS

# machine- and moment-dependent: left out of determinism checks
TIMING_COLUMNS = ("wall_s", "cpu_s", "ms_per_step", "cpu_ms_per_step", "ms_per_frame", "cpu_ms_per_frame", "filter_s",
                  "cpu_filter_s", "fps", "load_1m", "reference_ms", "computed_at")
BACKENDS = ("loky", "threading", "dask", "ray")
CLUSTER_PACKAGES = {"dask": "distributed", "ray": "ray"}  # the import each cluster backend needs
# ray's joblib backend returns whole lists only (no return_as="generator_unordered"): its records are
# sent back, and stored, a batch of RUNS_PER_WORKER runs per worker at a time
LIST_ONLY_BACKENDS = ("ray",)
RUNS_PER_WORKER = 2
STOP_S = 1.0  # an interrupted local dask worker is killed after this long, its run unfinished


class BackendError(RuntimeError):
    """A parallel backend that cannot be used as configured; the message is meant for the user as is."""


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


def check_backend(backend: str, address: str | None = None) -> None:
    """Fail at once, before any work, on a backend that cannot run here (no network access)."""
    if backend not in BACKENDS:
        raise BackendError(f"parallel.backend must be one of {', '.join(BACKENDS)}; got {backend!r}")
    if address and backend not in CLUSTER_PACKAGES:
        raise BackendError(
            f"parallel.address is for the {' and '.join(CLUSTER_PACKAGES)} backends, "
            f"not parallel.backend={backend}"
        )
    if address is not None and not isinstance(address, str):
        raise BackendError(f"parallel.address must be a string such as tcp://host:8786; got {address!r}")
    package = CLUSTER_PACKAGES.get(backend)
    if package and importlib.util.find_spec(package) is None:
        raise BackendError(f"parallel.backend={backend} needs the {package} package: pip install {package}")


@contextmanager
def parallel_backend(backend: str = "loky", n_jobs: int = 2, address: str | None = None) -> Iterator[None]:
    """The joblib configuration for ``backend``, with its cluster connected for the duration.

    ``n_jobs`` is the number of local workers (loky, threading, a local dask
    cluster); on an existing dask or ray cluster every worker is used.
    """
    check_backend(backend, address)
    if backend == "dask":
        with _dask_client(address, n_jobs), parallel_config(backend="dask"):
            yield
    elif backend == "ray":
        with _ray_cluster(address), parallel_config(backend="ray", n_jobs=-1 if address else n_jobs):
            yield
    elif backend == "loky":
        with parallel_config(backend="loky", n_jobs=n_jobs, initializer=start_worker, initargs=(os.getpid(),)):
            yield
    else:
        with parallel_config(backend=backend, n_jobs=n_jobs):
            yield


def _answers(address: str, seconds: float = 10.0) -> None:
    """A TCP connection to a cluster's ``host:port`` (``ray://host:port`` too) opens within ``seconds``, else
    OSError; ``auto`` and other names without a port are left to the cluster's own client."""
    host, _, port = address.removeprefix("ray://").rpartition(":")
    if host and port.isdigit():
        socket.create_connection((host, int(port)), timeout=seconds).close()


@contextmanager
def _ray_cluster(address: str | None) -> Iterator[None]:
    """ray connected for the duration, and shut down after if it was started here: the cluster at ``address``
    (first checked to answer), or, with no address, a new local cluster on the loopback alone
    (:func:`_ray_on_the_loopback`), never one named by ``RAY_ADDRESS`` or by a file a past one left."""
    import ray

    _register_ray()
    if ray.is_initialized():  # a session of the caller's own: used as it is, and left running
        yield
        return
    if address:  # ray.init retries an address that does not answer for minutes, printing every 5 s
        try:
            _answers(address)
        except OSError as error:
            raise BackendError(f"cannot reach ray at parallel.address={address}: {_one_line(error)}") from None
    with nullcontext() if address else _ray_on_the_loopback():
        try:
            with _sigterm_kept(), warnings.catch_warnings():
                warnings.filterwarnings("ignore", category=FutureWarning, module=r"ray\.")  # ray's tips, each start
                ray.init(address=address or "local", log_to_driver=False, logging_level=logging.ERROR,
                         **({} if address else {"include_dashboard": False}))  # the runner never reads it
        except (ConnectionError, RuntimeError, ValueError) as error:
            where = f"ray at parallel.address={address}" if address else "ray on this machine"
            hint = " (a cluster with token authentication also needs RAY_AUTH_MODE=token here)" if address else ""
            raise BackendError(f"cannot start or reach {where}: {_one_line(error)}{hint}") from None
        try:
            node = ray.util.get_node_ip_address()
            if not (address or ipaddress.ip_address(node).is_loopback):
                raise BackendError(f"a local ray cluster started on {node}, not on the loopback (127.0.0.1): this "
                                   f"ray release ignores {RAY_LOCAL_ONLY}=0; use parallel.backend=dask")
            yield
        finally:
            ray.shutdown()


def _register_ray() -> None:
    """ray's joblib backend as ``ray``, aborting (an interrupt, a run's error) without a new pool: joblib leaves
    the pool of a ``with Parallel()`` block ready for more work, which for ray's actors takes 10 s and more on
    a loaded machine, after a SIGTERM too; the runner submits nothing to a pool after an abort."""
    from ray.util.joblib.ray_backend import RayBackend

    class Stopping(RayBackend):
        def abort_everything(self, ensure_ready: bool = True) -> None:
            super().abort_everything(ensure_ready=False)

    register_parallel_backend("ray", Stopping)


RAY_LOCAL_ONLY = "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"  # "0": ray without clusters, its node on the loopback


@contextmanager
def _ray_on_the_loopback() -> Iterator[None]:
    """While it lasts, a local ray cluster takes the loopback (127.0.0.1) for its node's address, and every
    service it starts (GCS, raylet, object manager, workers, agents) listens there alone, as a local dask
    cluster does.  On Linux ray takes the machine's own address instead and listens on every interface; it
    takes the loopback where clusters of several machines are not enabled (:data:`RAY_LOCAL_ONLY` ``=0``,
    macOS's and Windows's default).  The processes ray starts read that variable from their environment;
    this process read it once, when ray was imported, into the constant set here too."""
    from ray._private import ray_constants

    saved = os.environ.get(RAY_LOCAL_ONLY), ray_constants.ENABLE_RAY_CLUSTER
    os.environ[RAY_LOCAL_ONLY], ray_constants.ENABLE_RAY_CLUSTER = "0", False
    try:
        yield
    finally:
        ray_constants.ENABLE_RAY_CLUSTER = saved[1]
        if saved[0] is None:
            os.environ.pop(RAY_LOCAL_ONLY, None)
        else:
            os.environ[RAY_LOCAL_ONLY] = saved[0]


@contextmanager
def _sigterm_kept() -> Iterator[None]:
    """This process's SIGTERM handler put back after the block.  ``ray.init`` installs its own, twice: one
    that exits at once, and its core worker's, which aborts: either would leave ray's processes and the
    workers' runs behind, where the runner's (:func:`~replication.runner.lifeline.stop_on_sigterm`) stops
    them and keeps every run stored."""
    previous = signal.getsignal(signal.SIGTERM)
    try:
        yield
    finally:
        if previous is not None and threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGTERM, previous)


@contextmanager
def _interrupts_ignored() -> Iterator[None]:
    """SIGINT ignored while worker processes start, so that they keep ignoring it (an ignored
    signal stays ignored across exec, and Python leaves it so); restored afterwards."""
    if threading.current_thread() is not threading.main_thread():
        yield  # only the main thread may set handlers; it is the one a Ctrl-C reaches anyway
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


@contextmanager
def _dask_client(address: str | None, n_jobs: int) -> Iterator[None]:
    from distributed import Client, LocalCluster

    cluster = None
    try:
        if address:
            client = Client(address)
        else:
            with _interrupts_ignored():  # the workers inherit it: Ctrl-C is for this process alone
                cluster = LocalCluster(
                    n_workers=n_jobs if n_jobs > 0 else None,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address="127.0.0.1:0",  # the dashboard too on the loopback alone, as the scheduler
                    silence_logs=logging.ERROR,
                )
            client = Client(cluster)
    except (OSError, TimeoutError, ValueError) as error:
        if cluster is not None:
            cluster.close()
        where = f"the dask scheduler at parallel.address={address}" if address else "a local dask cluster"
        raise BackendError(f"cannot reach {where}: {_one_line(error)}") from None
    try:
        yield
    except BaseException:  # interrupted: stop the local workers now, not once their runs end (a nanny waits 4 s)
        if cluster is not None:
            cluster.sync(_stop_now, cluster)
        raise
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


async def _stop_now(cluster) -> None:
    """Close a local dask cluster's workers at once: each nanny kills its worker's process after
    :data:`STOP_S`, mid-run (a process slow to be reaped is left to the cluster's own close)."""
    await asyncio.gather(*(nanny.close(timeout=STOP_S) for nanny in cluster.workers.values()), return_exceptions=True)


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


def _one_line(error: BaseException) -> str:
    return " ".join(str(error).split()) or error.__class__.__name__


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
    by_id = {run.run_id: run for run in pending}
    bar = tqdm(
        total=len(runs),
        initial=len(runs) - len(pending),
        desc=runs[0].experiment,
        unit="run",
        disable=not progress,
        mininterval=1.0,
    )
    with bar, parallel_backend(backend, n_jobs, address), closing(
        _records(pending, streamed=backend not in LIST_ONLY_BACKENDS)
    ) as records:
        for record in records:
            run = by_id[record["run_id"]]
            if "failure" in record:
                store.write_failure(run, record["failure"])
            else:
                store.write(run, record)
            bar.update()
    return len(pending)
