"""How a process that computes runs is set up: freed memory kept for reuse, and one thread (BLAS's and
OpenCV's).

Keep freed memory in the process instead of handing it back to the OS at every ``free``.

A filter step allocates the same large temporaries every frame (an (N, B + 1)
count table per likelihood call, an N x N potential table per MRF pair).
glibc serves blocks over its mmap threshold (128 kB at first) with fresh
``mmap`` pages and trims the heap's free top back to the OS, so each frame
page-faults those arrays in again; in this machine's VM that made the bis_pf
runs 2-3 times slower (docs/vision.md, "Speed").  Raising both thresholds
(``mallopt``, M_MMAP_THRESHOLD and M_TRIM_THRESHOLD: the same effect as the
``MALLOC_MMAP_THRESHOLD_`` and ``MALLOC_TRIM_THRESHOLD_`` environment
variables, but settable after start, in any worker) lets the heap reuse them.
The numbers computed do not change.  No effect off glibc.
"""

import ctypes
import ctypes.util
from functools import cache

from threadpoolctl import threadpool_limits

M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3  # glibc's <malloc.h>
MMAP_THRESHOLD = 32 * 2**20  # glibc's maximum on 64-bit: blocks above it still get their own mapping
TRIM_THRESHOLD = 64 * 2**20  # at most this much free memory is kept at the heap's top (loky restarts a worker grown by 300 MB)


@cache
def retain_freed_memory() -> bool:
    """Set the two glibc thresholds for this process (once); whether it took effect."""
    name = ctypes.util.find_library("c")
    try:
        mallopt = ctypes.CDLL(name).mallopt
    except (OSError, AttributeError, TypeError):  # not glibc (macOS, musl without mallopt, Windows)
        return False
    return bool(mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD)) and bool(mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD))


@cache
def one_thread() -> None:
    """Every run computes on one thread, BLAS's and OpenCV's, in whichever process computes it.

    BLAS: loky's workers get one thread each (two cores, two jobs), but a run computed in the main process
    (``n_jobs=1``) had every core: OpenBLAS then splits a product differently and the sums come out in
    another order, so the grid filter's RMSE at T = 100 differed in its last bit between one job and two
    (5.902905369091446 against ...445, one run of ungm_horizon's 1500).

    OpenCV: loky limits BLAS and OpenMP, not OpenCV's own pool of pthreads, which kept a thread per core
    in every worker; its threads spin while they wait, so two workers on two cores ran up to four busy
    threads.  One MIL run (hspf, CarScale) took 7.1 s and 11.7 CPU-seconds so, 6.4 s and 6.4 on one
    thread.  OpenCV splits its work by pixels or samples, each computed alone, so the numbers do not
    change: hspf's runs at paper scale were identical in every column but the timings.

    The limits stay on for the process (once is enough; the libraries are loaded by then)."""
    threadpool_limits(limits=1, user_api="blas")
    import cv2  # here: the command line checks a request before anything heavy is imported

    cv2.setNumThreads(1)
