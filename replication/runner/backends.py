"""Where runs are computed: each joblib backend as a :class:`Backend` registered by name in :data:`BACKENDS`,
with its cluster connected for the duration.

``parallel.backend`` (``conf/config.yaml``) names one: ``loky`` worker processes on this machine (the default),
``threading``, or a cluster: ``dask`` (a ``distributed`` scheduler at ``parallel.address``, started as a cluster
is, ``dask scheduler`` and ``dask worker`` on their command lines; or a local cluster of ``n_jobs`` worker
processes on the loopback when no address is given) or ``ray`` (``ray.init(address=parallel.address)``, a
cluster started with ``ray start --head``, its address first checked to answer; no address: a new local
cluster on the loopback, never a stale one a past run left named in ray's files; ray's joblib backend cannot
stream results, so its records come back a batch at a time).  The runner (:mod:`.execute`) asks only for a
backend by name and whether it streams.
"""

import asyncio
import importlib.util
import ipaddress
import logging
import os
import signal
import socket
import threading
import time
import warnings
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager, contextmanager, nullcontext
from dataclasses import dataclass

from joblib import parallel_config, register_parallel_backend

from replication.environment import variables
from replication.kinds import Registry
from replication.runner import lifeline

STOP_S = 1.0  # an interrupted local dask worker is killed after this long, its run unfinished


class BackendError(RuntimeError):
    """A parallel backend that cannot be used as configured; the message is meant for the user as is."""


class WorkerLost(BackendError):
    """A worker process ended in mid-run (killed, out of memory, its machine gone) and the backend gave up on
    its runs; the runs stored before it are kept, and the same command computes the rest."""


@dataclass(frozen=True)
class Backend:
    """A place runs are computed: ``connected(n_jobs, address)`` configures joblib for it (its cluster
    connected) for the duration; ``package``, the import it needs (a cluster's); ``streams``, whether records
    come back one at a time (ray's joblib backend returns whole lists only); ``lost``, the exceptions it
    raises when a worker process dies in mid-run (imported when asked); ``clustered``, whether
    ``parallel.address`` may name one."""

    connected: Callable[[int, str | None], AbstractContextManager]
    package: str | None = None
    streams: bool = True
    lost: Callable[[], tuple[type[BaseException], ...]] = tuple  # what it raises when a worker dies mid-run

    @property
    def clustered(self) -> bool:
        return self.package is not None


def check_backend(backend: str, address: str | None = None) -> None:
    """Fail at once, before any work, on a backend that cannot run here (no network access)."""
    if backend not in BACKENDS:
        raise BackendError(f"parallel.backend must be one of {', '.join(BACKENDS)}; got {backend!r}")
    if address and not BACKENDS[backend].clustered:
        raise BackendError(
            f"parallel.address is for the {' and '.join(CLUSTER_PACKAGES)} backends, "
            f"not parallel.backend={backend}"
        )
    if address is not None and not isinstance(address, str):
        raise BackendError(f"parallel.address must be a string such as tcp://host:8786; got {address!r}")
    package = BACKENDS[backend].package
    if package and importlib.util.find_spec(package) is None:
        raise BackendError(f"parallel.backend={backend} needs the {package} package: pip install {package}")


@contextmanager
def parallel_backend(backend: str = "loky", n_jobs: int = 2, address: str | None = None) -> Iterator[None]:
    """The joblib configuration for ``backend``, with its cluster connected for the duration.

    ``n_jobs`` is the number of local workers (loky, threading, a local dask
    cluster); on an existing dask or ray cluster every worker is used.
    """
    check_backend(backend, address)
    with BACKENDS[backend].connected(n_jobs, address):
        yield


@contextmanager
def _loky(n_jobs: int, address: str | None) -> Iterator[None]:
    """Worker processes on this machine, each watching this process so none outlives it (:mod:`.lifeline`)."""
    with parallel_config(backend="loky", n_jobs=n_jobs, initializer=lifeline.start_worker, initargs=(os.getpid(),)):
        yield


@contextmanager
def _threading(n_jobs: int, address: str | None) -> Iterator[None]:
    with parallel_config(backend="threading", n_jobs=n_jobs):
        yield


@contextmanager
def _dask(n_jobs: int, address: str | None) -> Iterator[None]:
    with _dask_client(address, n_jobs), parallel_config(backend="dask"):
        yield


@contextmanager
def _ray(n_jobs: int, address: str | None) -> Iterator[None]:
    with _ray_cluster(address), parallel_config(backend="ray", n_jobs=-1 if address else n_jobs):
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
    (:func:`_local_ray_cluster`), never one named by ``RAY_ADDRESS`` or by a file a past one left."""
    import ray

    _register_ray()
    if ray.is_initialized():  # a session of the caller's own: used as it is, and left running
        yield
        return
    if address:  # ray.init retries an address that does not answer for minutes, printing every 5 s
        try:
            _answers(address)
        except OSError as error:
            raise BackendError(f"cannot reach ray at parallel.address={address}: {one_line(error)}") from None
    with nullcontext() if address else _local_ray_cluster():
        before = lifeline.children()
        try:
            with _sigterm_kept(), warnings.catch_warnings():
                warnings.filterwarnings("ignore", category=FutureWarning, module=r"ray\.")  # ray's tips, each start
                ray.init(address=address or "local", log_to_driver=False, logging_level=logging.ERROR,
                         **({} if address else {"include_dashboard": False}))  # the runner never reads it
        except (ConnectionError, RuntimeError, ValueError) as error:
            where = f"ray at parallel.address={address}" if address else "ray on this machine"
            hint = " (a cluster with token authentication also needs RAY_AUTH_MODE=token here)" if address else ""
            raise BackendError(f"cannot start or reach {where}: {one_line(error)}{hint}") from None
        try:
            node = ray.util.get_node_ip_address()
            if not (address or ipaddress.ip_address(node).is_loopback):
                raise BackendError(f"a local ray cluster started on {node}, not on the loopback (127.0.0.1): this "
                                   f"ray release ignores {RAY_LOCAL_ONLY}=0; use parallel.backend=dask")
            yield
        finally:
            started = set() if address else lifeline.descendants(lifeline.children() - before)
            _settle_result_threads(RAY_SHUTDOWN_S)
            ray.shutdown()
            lifeline.end_within(started, RAY_SHUTDOWN_S)  # the agents its raylet starts may outlive it, under load


def _settle_result_threads(seconds: float) -> None:
    """Let ray's pool threads collect their last batches before ray shuts down (after an abort its actors are
    gone, so each gets its error at once): a thread still waiting then calls ray again, and ray's automatic
    ``ray.init()`` would start, or join, another cluster on this machine for it, and fail there."""
    from ray.util.multiprocessing.pool import ResultThread

    deadline = time.monotonic() + seconds
    for thread in [t for t in threading.enumerate() if isinstance(t, ResultThread)]:
        thread.join(max(0.0, deadline - time.monotonic()))


def _register_ray() -> None:
    """ray's joblib backend as ``ray``, aborting (an interrupt, a run's error) without a new pool: joblib leaves
    the pool of a ``with Parallel()`` block ready for more work, which for ray's actors takes 10 s and more on
    a loaded machine, after a SIGTERM too; the runner submits nothing to a pool after an abort."""
    from ray.util.joblib.ray_backend import RayBackend

    class Stopping(RayBackend):
        def abort_everything(self, ensure_ready: bool = True) -> None:
            super().abort_everything(ensure_ready=False)

    register_parallel_backend("ray", Stopping)


RAY_SHUTDOWN_S = 5.0  # after ray.shutdown(), the seconds a local cluster's processes have to end before SIGKILL
RAY_LOCAL_ONLY = "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"  # "0": ray without clusters, its node on the loopback
AT_NORMAL_PRIORITY = {"RAY_worker_niceness": "0"}  # ray's workers at its default nice 15 get a few per cent of
#                                                    a core beside any other busy process


@contextmanager
def _local_ray_cluster() -> Iterator[None]:
    """While it lasts, a local ray cluster takes the loopback (127.0.0.1) for its node's address, and every
    service it starts (GCS, raylet, object manager, workers, agents) listens there alone, as a local dask
    cluster does; and it starts its workers at the priority of other work (:data:`AT_NORMAL_PRIORITY`).  On
    Linux ray takes the machine's own address instead and listens on every interface; it takes the loopback
    where clusters of several machines are not enabled (:data:`RAY_LOCAL_ONLY` ``=0``, macOS's and Windows's
    default).  The processes ray starts read both from their environment; this process read the first once,
    when ray was imported, into the constant set here too."""
    from ray._private import ray_constants

    saved = ray_constants.ENABLE_RAY_CLUSTER
    ray_constants.ENABLE_RAY_CLUSTER = False
    try:
        with variables({RAY_LOCAL_ONLY: "0", **AT_NORMAL_PRIORITY}):
            yield
    finally:
        ray_constants.ENABLE_RAY_CLUSTER = saved


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
        raise BackendError(f"cannot reach {where}: {one_line(error)}") from None
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




def one_line(error: BaseException) -> str:
    """An exception's message on one line (its class's name when it has none)."""
    return " ".join(str(error).split()) or error.__class__.__name__


def _loky_lost() -> tuple[type[BaseException], ...]:
    from joblib.externals.loky.process_executor import TerminatedWorkerError

    return (TerminatedWorkerError,)


def _dask_lost() -> tuple[type[BaseException], ...]:
    """A task whose workers died more often than ``distributed.scheduler.allowed-failures`` (before that, the
    scheduler sends it to another worker)."""
    from distributed import KilledWorker

    return (KilledWorker,)


def _ray_lost() -> tuple[type[BaseException], ...]:
    from ray.exceptions import RayActorError, WorkerCrashedError

    return (RayActorError, WorkerCrashedError)


BACKENDS: Registry[Backend] = Registry("parallel backend", {
    "loky": Backend(_loky, lost=_loky_lost),
    "threading": Backend(_threading),
    "dask": Backend(_dask, package="distributed", lost=_dask_lost),
    "ray": Backend(_ray, package="ray", streams=False, lost=_ray_lost),
})
CLUSTER_PACKAGES = {name: b.package for name, b in BACKENDS.items() if b.clustered}  # the import each needs
