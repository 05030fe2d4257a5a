"""Means whose sums are rounded once (``math.fsum``): a score depends only on the numbers it averages.

A run's scores are means over frames, targets or time steps, computed once from its trajectory.  numpy
adds in an order of its own implementation (pairwise, in blocks of eight accumulators: the same on every
SIMD path of numpy 2.4, whose float reductions are not vectorised, but an order numpy may change);
``math.fsum`` returns the exact sum rounded once (Shewchuk's algorithm), which no summation order, machine
or library version changes.  It reads the values as Python floats: about a millisecond for the 16,000
distances of a 16-target run of 1000 frames, once per run.
"""

import math

import numpy as np


def fsum_mean(values) -> float:
    """The mean of ``values`` (any shape): their exact sum rounded once, over their count; NaN for none.
    Where no float holds the exact sum (an infinite or overflowing value), numpy's sum, as the mean was."""
    flat = np.asarray(values, dtype=float).ravel()
    if not flat.size:
        return float("nan")
    try:
        total = math.fsum(flat.tolist())
    except (OverflowError, ValueError):  # past the largest float, or inf - inf: inf or NaN, as numpy gives
        total = float(np.sum(flat))
    return total / flat.size
