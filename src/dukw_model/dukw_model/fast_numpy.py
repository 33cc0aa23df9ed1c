"""numpy's C entry points without their Python wrappers, for the per-step small arrays.

The simulator and the models call these thousands of times a simulated second on arrays
of a few dozen floats, where numpy's Python-level wrappers (the ``__array_function__``
dispatcher, ``ndarray.max``'s method wrapper, ``np.clip``'s argument handling) cost more
than the arithmetic. Each name is the very function its wrapper calls, so the results are
the same bits; where numpy hides the entry point, the public function stands in.

A ufunc given a Python float operand converts it at every call (numpy 2's scalar promotion:
~0.25 us on these arrays); a 0-d float64 array of the same value takes the same float64 loop
(the same bits) without that: ``operand`` makes one for a constant, and a per-step value is
written into a 0-d buffer (``buffer[()] = value``, ~0.03 us).
"""
from __future__ import annotations

import numpy as np

#: np.dot's C function (not @: the same BLAS call without matmul's ufunc overhead).
dot = getattr(np.dot, '_implementation', np.dot)
#: np.clip's ufunc (np.clip of floats calls it; same bits as minimum(maximum(x, lo), hi)).
clip = getattr(getattr(np, '_core', None), 'umath', np).clip
#: np.interp's C function (real values: the wrapper calls it).
interp = getattr(getattr(np, '_core', None), 'multiarray', np).interp
#: ndarray.max() / ndarray.sum(): the reductions the methods call.
max_of = np.maximum.reduce
sum_of = np.add.reduce
#: A NamedTuple from all its fields' values, without the class's Python __new__.
new_tuple = tuple.__new__


def operand(value: float) -> np.ndarray:
    """``value`` as a read-only 0-d float64 array, a constant operand of per-step ufuncs."""
    out = np.array(float(value))
    out.flags.writeable = False
    return out
