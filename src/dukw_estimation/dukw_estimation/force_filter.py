"""Kalman smoothing of a measured track force (current x gain), as the paper did before fitting.

A constant-velocity model [force, force rate] in filterpy's linear KalmanFilter (its state,
covariance and matrices). The predict and update are filterpy's equations written out with
the same numpy products in the same order (the results are bit-identical): its generic
calls cost more than the track-force step can afford (scipy's block_diag in
``Q_discrete_white_noise``, a deepcopy and a 1x1 ``inv`` per update; issue 16).
"""
from __future__ import annotations

import math

import numpy as np
from filterpy.kalman import KalmanFilter


_EYE2 = np.eye(2)


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
            self._predict(dt)
        self._update(force_n)
        self.t_s = t_s
        return True

    def _predict(self, dt: float) -> None:
        """filterpy's KalmanFilter.predict with F = [[1, dt], [0, 1]] and the discrete white
        noise Q of ``Q_discrete_white_noise(2, dt, process ** 2)``."""
        kf = self.kf
        kf.F = F = np.array([[1.0, dt], [0.0, 1.0]])
        kf.Q = Q = np.array([[.25 * dt ** 4, .5 * dt ** 3],
                             [.5 * dt ** 3, dt ** 2]]) * self.process_n_per_s ** 2
        kf.x = np.dot(F, kf.x)
        kf.P = np.dot(np.dot(F, kf.P), F.T) + Q

    def _update(self, force_n: float) -> None:
        """filterpy's KalmanFilter.update (Joseph form) for the one scalar measurement; the
        1x1 innovation covariance is inverted by a division, as LAPACK does it."""
        kf = self.kf
        H, R, P = kf.H, kf.R, kf.P
        y = np.array([[force_n]]) - np.dot(H, kf.x)
        PHT = np.dot(P, H.T)
        S = np.dot(H, PHT) + R
        K = np.dot(PHT, 1.0 / S)
        kf.x = kf.x + np.dot(K, y)
        I_KH = _EYE2 - np.dot(K, H)
        kf.P = np.dot(np.dot(I_KH, P), I_KH.T) + np.dot(np.dot(K, R), K.T)
