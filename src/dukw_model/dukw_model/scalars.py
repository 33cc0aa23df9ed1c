"""Which calls take the models' scalar fast paths (ROS-free).

The simulator and the estimator call the traction and hull-section models per track and
per step with plain numbers; wrapping those in 0-d arrays costs more than the physics.
"""
from __future__ import annotations

import numpy as np


def is_scalar(value) -> bool:
    """A plain number (float, int, numpy scalar or 0-d array): the scalar path applies."""
    if isinstance(value, (float, int)):
        return True
    ndim = getattr(value, 'ndim', None)      # arrays and numpy scalars: no np.ndim call
    return np.ndim(value) == 0 if ndim is None else ndim == 0
