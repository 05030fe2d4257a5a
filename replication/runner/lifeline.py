"""How the runner's processes end: no worker or companion outlives it, and SIGTERM stops it as Ctrl-C does.

A child process holds a *lifeline* (:func:`watch_parent`): a daemon thread that ends the process
(``os._exit``) within :data:`POLL_S` of its parent's death, however the parent died (``kill -9``
included) and whether the child is computing or waiting.  The loky workers get it through their
initializer (:func:`start_worker`), and their resource trackers exit
once no worker holds their pipe; a companion experiment (``also:``) gets it from the environment
its runner starts it with (:func:`child_environment`, :func:`watch_parent_from_environment`).  The
dask backend's local workers die with their parent already (distributed watches it); a local ray
cluster's processes are ended with it (:func:`end_within`), the agents its raylet starts included.
"""

import gc
import os
import signal
import threading
import time
from functools import cache
from pathlib import Path

PARENT_VARIABLE = "REPLICATION_PARENT_PID"  # set by a runner for the companion it starts
POLL_S = 0.5
_signal_received = signal.SIGINT  # the signal that interrupted this process, once one has


@cache  # one watch per process and parent, however often it is asked for
def watch_parent(parent: int) -> None:
    """Exit this process as soon as its parent is no longer process ``parent`` (it died, and this
    process was handed to another), checking every :data:`POLL_S` seconds from a daemon thread."""

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(POLL_S)
        os._exit(1)  # no clean-up: the parent that would read the results is gone

    threading.Thread(target=watch, name="lifeline", daemon=True).start()


def start_worker(runner: int) -> None:
    """A loky worker's initializer.  It ignores SIGINT: a terminal's Ctrl-C reaches the whole process
    group, and a worker caught waiting for its next run would print a traceback; the parent stops the
    workers.  And it exits as soon as ``runner`` (the process that started it) is gone.  It lives here,
    in a module that imports nothing heavy, because the worker imports the initializer's module before
    calling it: from the runner's module that would import the tasks and compile their numba kernels
    with SIGINT not yet ignored, and a Ctrl-C landing inside numba's compiler is printed, not raised."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    watch_parent(runner)


def child_environment() -> dict[str, str]:
    """This process's environment, naming it as the parent a child started with it must not outlive."""
    return {**os.environ, PARENT_VARIABLE: str(os.getpid())}


def watch_parent_from_environment() -> None:
    """In a process started with :func:`child_environment`: the lifeline to that parent (even if it died
    before this process got here).  No-op otherwise."""
    parent = os.environ.pop(PARENT_VARIABLE, None)  # not inherited further: a child of ours names us
    if parent:
        watch_parent(int(parent))


def stop_on_sigterm() -> None:
    """Handle SIGTERM as Ctrl-C: a KeyboardInterrupt in the main thread (workers stopped, stored runs
    kept); a second SIGTERM ends the process at once."""
    signal.signal(signal.SIGTERM, _interrupt)


def _interrupt(signum: int, frame) -> None:
    global _signal_received
    _signal_received = signum
    signal.signal(signum, signal.SIG_DFL)
    raise KeyboardInterrupt


def stop_children() -> None:
    """SIGTERM to every child of this process still running: one the runner's clean-up left behind, such as a
    loky worker caught starting (its interpreter not yet up to read its task, nor holding its lifeline), which
    Python's exit would otherwise wait for, seconds each.  A worker dies of it; a companion runner stops as
    after Ctrl-C; a resource tracker ignores it and ends when its last user has.  Linux (``/proc``) only."""
    for pid in children():
        try:
            os.kill(pid, signal.SIGTERM)
        except OSError:  # gone meanwhile, or not ours to signal
            continue


def _processes() -> dict[int, tuple[int, str]]:
    """Every live process's parent and state, from ``/proc`` (empty where there is none)."""
    table = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            state, parent = stat.read_text().rsplit(")", 1)[1].split()[:2]
            table[int(stat.parent.name)] = int(parent), state
        except (OSError, ValueError):  # gone meanwhile
            continue
    return table


def children() -> set[int]:
    """This process's running children (not zombies)."""
    return {pid for pid, (parent, state) in _processes().items() if parent == os.getpid() and state != "Z"}


def descendants(roots: set[int]) -> set[int]:
    """``roots`` still running, the processes they started, the ones those started, and so on."""
    table = _processes()
    found = layer = {pid for pid in roots if pid in table}
    while layer:
        layer = {pid for pid, (parent, _) in table.items() if parent in layer} - found
        found = found | layer
    return _running(found, table)


def _running(pids: set[int], table: dict[int, tuple[int, str]]) -> set[int]:
    return {pid for pid in pids if pid in table and table[pid][1] != "Z"}


def end_within(pids: set[int], seconds: float) -> None:
    """Wait up to ``seconds`` for ``pids`` to end by themselves, then SIGKILL every one left."""
    deadline = time.monotonic() + seconds
    while (left := _running(pids, _processes())) and time.monotonic() < deadline:
        time.sleep(0.05)
    for pid in left:
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:  # ended meanwhile
            continue


def exit_uncollected() -> None:
    """Let this process exit without Python's last garbage collection, which walks every object on the heap
    (numba's compiled kernels and their LLVM modules among them: 3-4 s of a runner's exit on a loaded
    machine, after a SIGTERM as after a finished run) only to free memory the process is handing back whole.
    Objects are still finalized as their modules are cleared."""
    gc.freeze()


def interrupt_status() -> int:
    """The exit status of an interrupted command, 128 + the signal, as a shell reports a process that
    signal killed: 130 after Ctrl-C (SIGINT), 143 after SIGTERM."""
    return 128 + _signal_received
