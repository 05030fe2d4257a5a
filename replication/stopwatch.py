"""Two clocks for one stretch of work: the wall clock and the CPU time of the thread doing it.

A run computes on one thread (one BLAS thread, :mod:`replication.runner.memory`), so its CPU time is
its own work whatever else the machine is doing, where its wall time also counts the time it waited
for a core: on a loaded machine the wall clock runs ahead, the thread's clock does not.  The papers
time with the wall clock; a claim about time is read with both (``ms_per_frame`` and
``cpu_ms_per_frame``, ...), and each run's record keeps the machine's load (``load_1m``) beside them.
"""

import os
import time


class Stopwatch:
    """Accumulates ``wall`` (``time.perf_counter``) and ``cpu`` (``time.thread_time``) seconds over
    every ``with stopwatch:`` block; ``last_wall`` is the wall time of the latest block."""

    __slots__ = ("wall", "cpu", "last_wall", "_wall", "_cpu")

    def __init__(self):
        self.wall = self.cpu = self.last_wall = 0.0

    def __enter__(self) -> "Stopwatch":
        self._wall, self._cpu = time.perf_counter(), time.thread_time()
        return self

    def __exit__(self, *exc) -> None:
        self.cpu += time.thread_time() - self._cpu
        self.last_wall = time.perf_counter() - self._wall
        self.wall += self.last_wall


def load_1m() -> float | None:
    """The machine's load average over the last minute: the processes running or waiting for a core
    (about 2 on a 2-core machine running one run per core and nothing else; above the cores, runs
    waited), or None where the system does not say."""
    try:
        return round(os.getloadavg()[0], 2)
    except OSError:
        return None
