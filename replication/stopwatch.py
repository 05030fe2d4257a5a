"""Two clocks for one stretch of work: the wall clock and the CPU time of the thread doing it.

A run computes on one thread (one BLAS thread, :mod:`replication.runner.memory`), so its CPU time is
its own work whatever else the machine is doing, where its wall time also counts the time it waited
for a core: on a loaded machine the wall clock runs ahead, the thread's clock does not.  The papers
time with the wall clock; a claim about time is read with both (``ms_per_frame`` and
``cpu_ms_per_frame``, ...), and each run's record keeps the machine's load (``load_1m``) beside them.

Neither clock sees a virtual machine's host slowing every core at once (its CPU time runs on while the
core is taken away): a run's record also keeps the time a fixed piece of work took on its worker about
then (``reference_ms``, :func:`machine_speed`), so that times recorded at different moments, or on
different machines, can be read against the speed the machine had.
"""

import math
import os
import time

import numpy as np

REFERENCE_EVERY_S = 60.0  # a worker times the reference work at its first run and then at most once a minute


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


def reference_ms(repeats: int = 3) -> float:
    """The milliseconds a fixed piece of work takes on this thread, the fastest of ``repeats``: a Python loop
    of 10^5 steps and numpy's exp over 10^5 numbers, the mix of interpreter and vector work a filter's step
    makes.  Its ratio between two recordings is the ratio of the machine's speeds."""
    values = np.linspace(0.0, 1.0, 100_000)
    best = math.inf
    for _ in range(repeats):
        started = time.perf_counter()
        total = 0
        for i in range(100_000):
            total += i
        np.exp(values)
        best = min(best, time.perf_counter() - started)
    return round(1000.0 * best, 3)


class _Every:
    """The latest of a measurement taken at most once every ``seconds`` in this process."""

    def __init__(self, measure, seconds: float):
        self.measure, self.seconds, self.at, self.value = measure, seconds, -math.inf, math.nan

    def __call__(self) -> float:
        now = time.monotonic()
        if now - self.at >= self.seconds:
            self.value, self.at = self.measure(), now
        return self.value


machine_speed = _Every(reference_ms, REFERENCE_EVERY_S)  # the reference work's ms on this worker, about now


def load_1m() -> float | None:
    """The machine's load average over the last minute: the processes running or waiting for a core
    (about 2 on a 2-core machine running one run per core and nothing else; above the cores, runs
    waited), or None where the system does not say."""
    try:
        return round(os.getloadavg()[0], 2)
    except OSError:
        return None
