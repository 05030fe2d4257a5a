"""The one timing rule of the benchmark scripts (``benchmark.py``, ``peers.py``)."""

import time


def best_of(call, repeats: int = 5) -> float:
    """Seconds of the fastest of ``repeats`` calls (the least disturbed by the rest of the machine)."""
    times = []
    for _ in range(repeats):
        started = time.perf_counter()
        call()
        times.append(time.perf_counter() - started)
    return min(times)
