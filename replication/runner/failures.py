"""Runs whose numbers are not finite fail, with the reason stored, instead of storing NaN.

A task's record is checked in the process that computed it (:func:`failure`): every number in it,
per-frame series included, must be finite, except the metrics of :data:`UNDEFINED`, which are NaN
(or infinite) by definition for some runs.  A run stopped by a number it needs that is not finite
(:class:`replication.errors.NotFinite`: NaN log-weights, say), or by a method that returns the wrong thing
(:class:`replication.errors.RunFailed`), fails the same way.  A failed run leaves
``<run id>.failed`` in the store (:meth:`replication.runner.store.Store.write_failure`) holding the
reason: it is not computed again, the report leaves it out of every statistic and counts it, and the
run command names each reason with its count and exits with status :data:`FAILED_STATUS`.  The same
config and seed fail the same way; a change of config or code gives new runs (new keys), computed afresh.
"""

import math
import sys
from collections.abc import Iterator

import numpy as np

from replication.run import Run

UNDEFINED = {  # metric: when it is undefined, and so stored as NaN (or inf) without failing the run
    "mean_ess": "a filter without particles (the point-mass grid) has no effective sample size",
    "visible_error": "tracking: no target is at least half visible in the frames judged",
    "motp": "MOT: no hypothesis matched a target",
    "mean_error_per_target": "MOT: no hypothesis matched a target",
    "fps": "MOT: a tracker timed at 0 s runs at infinitely many frames per second",
    "swaps_per_encounter": "tracking: no two targets came within a box width of each other",
    "tracked_error": "tracking: every target was lost from the first frame judged",
    "error_without_failure[lost]": "tracking: the run failed by that reading (Table 2 averages runs without failure)",
    "error_without_failure[swap]": "tracking: the run failed by that reading (Table 2 averages runs without failure)",
    "error_without_failure[drift]": "tracking: the run failed by that reading (Table 2 averages runs without failure)",
}
FAILED_STATUS = 3  # the run command's exit status when runs failed (2: a bad request; 130, 143: interrupted)
SHOWN = 3  # numbers named in a reason


def failure(record: dict) -> str | None:
    """Why ``record`` (a task's metrics) cannot be stored, e.g. ``not finite: rmse=nan``; None if it can."""
    bad = {}
    for key, value in _non_finite(record):
        if key not in UNDEFINED:
            bad.setdefault(key, value)
    if not bad:
        return None
    named = sorted(bad, key=lambda key: "." in key)  # the metrics first, then the per-frame series
    shown = ", ".join(f"{key}={bad[key]}" for key in named[:SHOWN])
    return f"not finite: {shown}" + (f" and {len(bad) - SHOWN} more" if len(bad) > SHOWN else "")


def _non_finite(value, key: str = "") -> Iterator[tuple[str, float]]:
    """Every float in ``value`` that is not finite, with its key (nested keys joined by dots; a list's items
    share its key), in the order of the record.  A list of numbers (a per-frame series, nested or not) is
    checked as one array; a list holding anything else (None, strings, mappings) item by item."""
    if isinstance(value, dict):
        for name, item in value.items():
            yield from _non_finite(item, f"{key}.{name}" if key else str(name))
    elif isinstance(value, (list, tuple)):
        numbers = _numeric(value)
        if numbers is None:
            for item in value:
                yield from _non_finite(item, key)
        elif numbers.dtype.kind == "f":  # ints and booleans are finite
            for item in numbers[~np.isfinite(numbers)]:
                yield key, float(item)
    elif isinstance(value, (float, np.floating)) and not math.isfinite(value):
        yield key, float(value)


def _numeric(items: list | tuple) -> np.ndarray | None:
    """``items`` as one array (row-major, the order of the list) if they are all numbers in a regular
    nesting, else None."""
    try:
        array = np.asarray(items)
    except ValueError:  # ragged
        return None
    return array.reshape(-1) if array.dtype.kind in "fiub" else None


def exit_if_failed(store, runs: list[Run]) -> None:
    """One line on stderr per reason with the number of ``runs`` that failed for it in ``store`` (a
    :class:`~replication.runner.store.Store`, which imports this module to check records), then exit with
    :data:`FAILED_STATUS`; nothing if none failed."""
    failures = store.failures(runs)
    for reason, count in failures.most_common():
        print(f"failed: {count} runs of {runs[0].experiment}: {reason}", file=sys.stderr)
    if failures:
        raise SystemExit(FAILED_STATUS)
