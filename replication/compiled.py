"""Scalar functions compiled into numpy ufuncs, for the hot elementwise arithmetic of the SMC core and models."""

from numba import vectorize


def elementwise(signature: str):
    """A scalar function compiled into a numpy ufunc (numba's ``vectorize`` for one signature): one pass
    over its arrays without temporaries, broadcasting like numpy's own, called without numba's dispatcher
    (1 us a call, not 2).  Written in numpy's operations and order, it gives numpy's bits."""
    return lambda function: vectorize([signature], cache=True)(function).ufunc
