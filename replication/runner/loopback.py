"""A dask or ray cluster on this machine's loopback, started from the command lines a real cluster's
processes are started with (``dask scheduler`` / ``dask worker``, ``ray start --head``): for trying
``parallel.backend=dask|ray`` with ``parallel.address=`` before a cluster is at hand, and for the tests
and ``benchmarks/cluster.py``, which run the command line against it as a user's cluster would be.
"""

import os
import shutil
import socket
import subprocess
import sys
import time
from collections.abc import Iterator, Mapping
from contextlib import contextmanager

from replication.runner.backends import AT_NORMAL_PRIORITY

QUIET = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
START_S = 120.0  # a cluster that has not come up within this is reported, not waited for


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on now."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def command_line(name: str) -> str:
    """The console script ``name`` of this interpreter's environment (``dask``, ``ray``)."""
    found = shutil.which(name, path=os.path.dirname(sys.executable))
    if found is None:
        raise RuntimeError(f"{name} is not installed beside {sys.executable} (pip install -e '.[cluster]')")
    return found


@contextmanager
def dask_cluster(workers: int) -> Iterator[str]:
    """A ``dask scheduler`` and ``workers`` ``dask worker`` processes of one thread each (as the runner's
    workers: one run at a time); yields the scheduler's address once every worker has joined.  The
    workers are stopped first, then the scheduler."""
    from distributed import Client

    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    started = [subprocess.Popen([command_line("dask"), "scheduler", "--host", "127.0.0.1", "--port", str(port),
                                 "--dashboard-address", "127.0.0.1:0", "--no-show"], **QUIET)]
    try:
        started += [subprocess.Popen([command_line("dask"), "worker", address, "--nthreads", "1", "--host",
                                      "127.0.0.1", "--dashboard-address", "127.0.0.1:0", "--name", f"worker-{i}"],
                                     **QUIET)
                    for i in range(workers)]
        with Client(address, timeout=60) as client:
            client.wait_for_workers(workers, timeout=START_S)
        yield address
    finally:
        for process in reversed(started):
            process.terminate()
            process.wait(timeout=60)


@contextmanager
def ray_cluster(workers: int, env: Mapping[str, str] | None = None) -> Iterator[str]:
    """``ray start --head --num-cpus=workers --block`` under ``env`` (this process's environment if None;
    the processes that join the head need the same ``RAY_AUTH_TOKEN`` and ``RAY_TMPDIR``); yields its
    address once ``ray status`` answers.  Ending the blocking head stops every process it started.  Its
    workers run at the priority of other work, as the runner's own local cluster's do
    (:data:`~replication.runner.backends.AT_NORMAL_PRIORITY`)."""
    env = {**(os.environ if env is None else env), **AT_NORMAL_PRIORITY}
    port = free_port()
    address = f"127.0.0.1:{port}"
    head = subprocess.Popen([command_line("ray"), "start", "--head", f"--port={port}", f"--num-cpus={workers}",
                             "--include-dashboard=false", "--disable-usage-stats", "--block"], env=env, **QUIET)
    try:
        deadline = time.monotonic() + START_S
        while subprocess.run([command_line("ray"), "status", f"--address={address}"], env=env,
                             capture_output=True).returncode:
            if head.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f"the ray head node on {address} did not come up")
            time.sleep(1)
        yield address
    finally:
        head.terminate()
        head.wait(timeout=60)
