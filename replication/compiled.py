"""The project's numba conventions: scalar functions compiled into numpy ufuncs, and, for compiled kernels
that must give numpy's bits, numpy's own order of a sum and its BLAS calls.

A sum's rounding depends on the order of its additions.  BLAS (``np.dot``, ``@``) picks its order by the
CPU it finds (OpenBLAS's Haswell, SkylakeX and Sandybridge kernels each split a dot product into other
partial sums) and by its thread count, so a weighted mean or an ESS computed with it differs in the last
digits between an AVX2 and an AVX-512 machine, or between one BLAS thread and two.  ``np.sum`` does not:
its pairwise summation (numpy's ``pairwise_sum``, ``loops_utils.h.src``) fixes the order from N alone,
blocks of at most 128 terms summed by eight accumulators and halved at multiples of 8, whatever SIMD width
the CPU has.  :func:`pairwise_sum` is that order, bit for bit (``np.sum(values)``); a kernel that makes
its terms as it goes (:mod:`replication.smc.weights`) walks the same tree (:func:`half`) and sums each
leaf of at most :data:`BLOCK` terms with :func:`block_sum`, so a weighted sum costs one pass with no
temporary array.  Numba compiles it without fast-math, so no CPU's code reassociates the additions or
fuses a product into them.  (Recursive kernels load back from numba's cache: checked across modules.)
"""

import numpy as np
from numba import njit, vectorize


def elementwise(signature: str):
    """A scalar function compiled into a numpy ufunc (numba's ``vectorize`` for one signature): one pass
    over its arrays without temporaries, broadcasting like numpy's own, called without numba's dispatcher
    (1 us a call, not 2).  Written in numpy's operations and order, it gives numpy's bits."""
    return lambda function: vectorize([signature], cache=True)(function).ufunc


BLOCK = 128  # numpy's PW_BLOCKSIZE: a leaf of the pairwise tree


@njit(cache=True)
def block_sum(values):
    """Numpy's sum of at most :data:`BLOCK` numbers: in order below 8, else eight running sums over the whole
    eights, combined as ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7)), then the rest in order."""
    n = values.size
    if n < 8:
        total = -0.0
        for i in range(n):
            total += values[i]
        return total
    r0, r1, r2, r3 = values[0], values[1], values[2], values[3]
    r4, r5, r6, r7 = values[4], values[5], values[6], values[7]
    whole = n - n % 8
    for i in range(8, whole, 8):
        r0 += values[i]
        r1 += values[i + 1]
        r2 += values[i + 2]
        r3 += values[i + 3]
        r4 += values[i + 4]
        r5 += values[i + 5]
        r6 += values[i + 6]
        r7 += values[i + 7]
    total = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    for i in range(whole, n):
        total += values[i]
    return total


@njit(cache=True)
def half(n):
    """Where numpy splits n > :data:`BLOCK` terms: n // 2 rounded down to a multiple of 8."""
    h = n // 2
    return h - h % 8


@njit(cache=True)
def _tree(values):
    if values.size <= BLOCK:
        return block_sum(values)
    h = half(values.size)
    return _tree(values[:h]) + _tree(values[h:])


@njit(cache=True)
def pairwise_sum(values):
    """``np.sum(values)`` of a 1-D float64 array, bit for bit: numpy adds the tree's sum to its identity 0.0."""
    return 0.0 + _tree(values)


@njit(cache=True)
def matvec(matrix, vector):
    """``matrix @ vector`` as numpy computes it: BLAS's dot product for a one-row matrix, its matrix-vector
    product otherwise, for a C- or F-contiguous matrix (numba calls the same BLAS kernels: tested)."""
    if matrix.shape[0] == 1:
        return np.array([np.dot(np.ascontiguousarray(matrix[0]), vector)])
    return np.dot(matrix, vector)
