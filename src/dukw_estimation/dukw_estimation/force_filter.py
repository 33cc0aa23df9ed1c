"""Kalman smoothing of a measured track force (current x gain), as the paper did before fitting.

A constant-velocity model [force, force rate] in filterpy's linear KalmanFilter.
"""
from __future__ import annotations

import math

import numpy as np
from filterpy.common import Q_discrete_white_noise
from filterpy.kalman import KalmanFilter


class ForceSmoother:
    """Smooths one track's measured force, N. Non-finite measurements are ignored."""

    def __init__(self, process_n_per_s: float, measurement_n: float) -> None:
        if process_n_per_s <= 0.0 or measurement_n <= 0.0:
            raise ValueError('ForceSmoother needs positive noise sigmas')
        self.process_n_per_s = process_n_per_s
        self.kf = KalmanFilter(dim_x=2, dim_z=1)
        self.kf.H = np.array([[1.0, 0.0]])
        self.kf.R = np.array([[measurement_n ** 2]])
        self.kf.P = np.diag([1e6, 1e6])
        self.t_s: float | None = None

    @property
    def force_n(self) -> float:
        """The smoothed force (NaN before the first measurement)."""
        return float(self.kf.x[0, 0]) if self.t_s is not None else math.nan

    def update(self, t_s: float, force_n: float) -> bool:
        """Fuse one measurement at ``t_s``; False (and no change) when it is unusable."""
        if not (math.isfinite(force_n) and math.isfinite(t_s)):
            return False
        if self.t_s is None:
            self.kf.x = np.array([[force_n], [0.0]])
            self.kf.P = np.diag([self.kf.R[0, 0], 1e4])
            self.t_s = t_s
            return True
        dt = t_s - self.t_s
        if dt < 0.0:
            return False
        if dt > 0.0:
            self.kf.F = np.array([[1.0, dt], [0.0, 1.0]])
            self.kf.Q = Q_discrete_white_noise(2, dt, self.process_n_per_s ** 2)
            self.kf.predict()
        self.kf.update(np.array([[force_n]]))
        self.t_s = t_s
        return True
