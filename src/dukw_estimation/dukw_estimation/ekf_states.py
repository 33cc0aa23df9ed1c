"""The motion EKF's state vector: which state sits where (``ekf.MotionEkf``'s ``x`` and
``P``, and the compiled kernels of ``ekf_kernels``, which read it as plain ints)."""
from __future__ import annotations

from enum import IntEnum


class Idx(IntEnum):
    """Positions in the state vector."""

    X = 0
    Y = 1
    YAW = 2
    U = 3
    V = 4
    R = 5
    BIAS = 6
    S = 7
    ETA = 8
    ETA_RATE = 9
    GPS_BIAS_E = 10
    GPS_BIAS_N = 11
    SOIL = 12
    ACCEL_BIAS_X = 13
    ACCEL_BIAS_Y = 14
    HEAVE = 15
    HEAVE_RATE = 16


N_STATES = len(Idx)
