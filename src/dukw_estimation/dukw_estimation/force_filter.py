"""Kalman smoothing of a measured track force (current x gain), as the paper did before fitting.

A constant-velocity model [force, force rate]: filterpy's linear KalmanFilter's predict
(F = [[1, dt], [0, 1]], Q = ``Q_discrete_white_noise(2, dt, process ** 2)``) and update
(Joseph form, H = [1, 0]) written out on the six scalars of its state and covariance.
filterpy's generic calls (scipy's block_diag in ``Q_discrete_white_noise``, a deepcopy and a
1x1 ``inv`` per update) and even the same products on 2x2 numpy arrays cost 10-15 us a
track per status, where the scalars cost under 1 us (issue 16); the results agree with
filterpy's to rounding (test_hot_paths: 1e-12 relative over 3000 random steps).
"""
from __future__ import annotations

import math


class ForceSmoother:
    """Smooths one track's measured force, N. Non-finite measurements are ignored.

    ``x``: [force N, force rate N/s]; ``P``: its covariance, row-major [p00, p01, p10, p11]
    (kept as filterpy keeps it, not forced symmetric)."""

    def __init__(self, process_n_per_s: float, measurement_n: float) -> None:
        if process_n_per_s <= 0.0 or measurement_n <= 0.0:
            raise ValueError('ForceSmoother needs positive noise sigmas')
        self.process_var = process_n_per_s ** 2
        self.measurement_var = measurement_n ** 2
        self.x = [0.0, 0.0]
        self.P = [1e6, 0.0, 0.0, 1e6]
        self.t_s: float | None = None

    @property
    def force_n(self) -> float:
        """The smoothed force (NaN before the first measurement)."""
        return self.x[0] if self.t_s is not None else math.nan

    def update(self, t_s: float, force_n: float) -> bool:
        """Fuse one measurement at ``t_s``; False (and no change) when it is unusable."""
        if not (math.isfinite(force_n) and math.isfinite(t_s)):
            return False
        if self.t_s is None:
            self.x = [force_n, 0.0]
            self.P = [self.measurement_var, 0.0, 0.0, 1e4]
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
        """x = F x, P = F P F' + Q."""
        p00, p01, p10, p11 = self.P
        q = self.process_var
        force, rate = self.x
        self.x = [force + dt * rate, rate]
        a00, a01 = p00 + dt * p10, p01 + dt * p11           # F P
        self.P = [a00 + a01 * dt + 0.25 * dt ** 4 * q, a01 + 0.5 * dt ** 3 * q,
                  p10 + p11 * dt + 0.5 * dt ** 3 * q, p11 + dt ** 2 * q]

    def _update(self, force_n: float) -> None:
        """The scalar measurement of the force: gain K = P H' / (H P H' + R); Joseph form
        P = (I - K H) P (I - K H)' + K R K'."""
        p00, p01, p10, p11 = self.P
        r = self.measurement_var
        innovation = force_n - self.x[0]
        s = p00 + r
        k0, k1 = p00 / s, p10 / s
        self.x = [self.x[0] + k0 * innovation, self.x[1] + k1 * innovation]
        b00, b10 = 1.0 - k0, -k1                             # I - K H = [[b00, 0], [b10, 1]]
        c00, c01 = b00 * p00, b00 * p01                      # (I - K H) P
        c10, c11 = b10 * p00 + p10, b10 * p01 + p11
        self.P = [c00 * b00 + k0 * r * k0, c00 * b10 + c01 + k0 * r * k1,
                  c10 * b00 + k1 * r * k0, c10 * b10 + c11 + k1 * r * k1]
