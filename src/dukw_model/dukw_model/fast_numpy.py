"""numpy's C entry points without their Python wrappers, for the per-step small arrays.

The simulator and the models call these thousands of times a simulated second on arrays
of a few dozen floats, where numpy's Python-level wrappers (the ``__array_function__``
dispatcher, ``ndarray.max``'s method wrapper, ``np.clip``'s argument handling) cost more
than the arithmetic. Each name is the very function its wrapper calls, so the results are
the same bits; where numpy hides the entry point, the public function stands in.
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
