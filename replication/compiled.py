"""The project's numba conventions: scalar functions compiled into numpy ufuncs, and, for compiled kernels
that must give numpy's bits, numpy's own order of a sum and its BLAS calls."""

from functools import lru_cache

import numpy as np
from numba import njit, vectorize


def elementwise(signature: str):
    """A scalar function compiled into a numpy ufunc (numba's ``vectorize`` for one signature): one pass
    over its arrays without temporaries, broadcasting like numpy's own, called without numba's dispatcher
    (1 us a call, not 2).  Written in numpy's operations and order, it gives numpy's bits."""
    return lambda function: vectorize([signature], cache=True)(function).ufunc


@lru_cache(maxsize=64)
def pairwise_program(n: int) -> np.ndarray:
    """numpy's order of summation of n contiguous values (``ndarray.sum``: pairwise, halves cut at
    multiples of 8, down to blocks of at most 128) as a postfix program of rows (start, size): a block
    to sum, or (0, -1), add the last two sums.  Built once per n, so that :func:`pairwise_sum` needs no
    recursion (a recursive function compiled with ``cache=True`` crashed numba when loaded back).
    Read-only: one array serves every caller."""
    program = []

    def visit(start, size):
        if size <= 128:
            program.append((start, size))
            return
        half = size // 2
        half -= half % 8
        visit(start, half)
        visit(start + half, size - half)
        program.append((0, -1))

    visit(0, n)
    made = np.array(program, dtype=np.int64).reshape(-1, 2)
    made.flags.writeable = False
    return made


@njit(cache=True)
def _block_sum(values, start, n):
    """numpy's sum of at most 128 values: one by one under 8, else 8 running sums and a tail."""
    if n < 8:
        total = -0.0
        for i in range(start, start + n):
            total += values[i]
        return total
    r0, r1, r2, r3 = values[start], values[start + 1], values[start + 2], values[start + 3]
    r4, r5, r6, r7 = values[start + 4], values[start + 5], values[start + 6], values[start + 7]
    i = start + 8
    end = start + n - n % 8
    while i < end:
        r0 += values[i]
        r1 += values[i + 1]
        r2 += values[i + 2]
        r3 += values[i + 3]
        r4 += values[i + 4]
        r5 += values[i + 5]
        r6 += values[i + 6]
        r7 += values[i + 7]
        i += 8
    total = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < start + n:
        total += values[i]
        i += 1
    return total


@njit(cache=True)
def pairwise_sum(values, program):
    """``values.sum()`` of a 1-D array in numpy's order (``program``: :func:`pairwise_program` of its
    length), to the last bit."""
    stack = np.empty(64)
    depth = 0
    for p in range(program.shape[0]):
        if program[p, 1] < 0:
            depth -= 1
            stack[depth - 1] = stack[depth - 1] + stack[depth]
        else:
            stack[depth] = _block_sum(values, program[p, 0], program[p, 1])
            depth += 1
    return stack[0]


@njit(cache=True)
def matvec(matrix, vector):
    """``matrix @ vector`` as numpy computes it: BLAS's dot product for a one-row matrix, its matrix-vector
    product otherwise, for a C- or F-contiguous matrix (numba calls the same BLAS kernels: tested)."""
    if matrix.shape[0] == 1:
        return np.array([np.dot(np.ascontiguousarray(matrix[0]), vector)])
    return np.dot(matrix, vector)
