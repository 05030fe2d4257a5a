"""The C library's exp, log and cos as numpy ufuncs: the same numbers on every CPU.

numpy computes ``np.exp`` and ``np.log`` of float64 with its own AVX-512 kernels where the CPU has AVX-512F
(``loops_exponent_log.dispatch.c.src``) and with the C library's functions elsewhere, and the two differ in
the last bit of some results; so an ESS or a log-evidence differed in its last digits between an AVX-512
and an AVX2 machine.  These call the C library on every CPU (numba compiles ``math.exp`` to a call of it;
with no vector math library in numba's LLVM nothing vectorises it into another), so they equal numpy's
results bit for bit on a machine without AVX-512 and take the C library's time, numpy's there too.
"""

import math

from replication.compiled import elementwise


@elementwise("float64(float64)")
def exp(x):
    return math.exp(x)


@elementwise("float64(float64)")
def log(x):
    """log 0 = -inf, the log of a negative number NaN, as numpy's."""
    return math.log(x) if x > 0.0 else (-math.inf if x == 0.0 else math.nan)


@elementwise("float64(float64)")
def cos(x):
    return math.cos(x)
