"""Which calls take the models' scalar fast paths (ROS-free).

The simulator and the estimator call the traction and hull-section models per track and
per step with plain numbers; wrapping those in 0-d arrays costs more than the physics.
"""
from __future__ import annotations

import numpy as np


def is_scalar(value) -> bool:
    """A plain number (float, int, numpy scalar or 0-d array): the scalar path applies."""
    return isinstance(value, (float, int)) or np.ndim(value) == 0
