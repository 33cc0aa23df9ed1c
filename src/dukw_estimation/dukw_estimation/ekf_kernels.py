"""The motion EKF's numeric kernels, compiled with numba (``ekf.MotionEkf`` calls them).

A 17-state prediction or scalar update is a few hundred floating-point operations; written
with numpy it was a dozen or more array calls of ~0.5-1 us each (the covariance's
F P F^T, the gain, the rank-1 correction), most of an IMU step's cost (issue 16). Here each
is one compiled call. ``cache=True`` keeps the machine code beside the module
(``__pycache__``), so a process loads it instead of compiling it again.

The products are summed in index order (not BLAS's blocked order), so the covariance can
differ from the numpy form in its last bits; the state's own prediction is the same
arithmetic as before.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from dukw_estimation.ekf_states import Idx

# state indices as plain ints: numba folds them in as constants when it compiles (its
# cache follows this file: a change of ekf_states.Idx needs the cache rebuilt, make setup)
_X, _Y, _YAW, _U, _V, _R = (int(Idx.X), int(Idx.Y), int(Idx.YAW), int(Idx.U), int(Idx.V),
                            int(Idx.R))
_S, _ETA, _ETA_RATE, _GBE, _GBN = (int(Idx.S), int(Idx.ETA), int(Idx.ETA_RATE),
                                   int(Idx.GPS_BIAS_E), int(Idx.GPS_BIAS_N))
_ABX, _ABY = int(Idx.ACCEL_BIAS_X), int(Idx.ACCEL_BIAS_Y)
_HZ, _HW = int(Idx.HEAVE), int(Idx.HEAVE_RATE)
#: ``predict``'s input modes: held, the IMU's accelerations, the drive model's target
HOLD, ACCEL, DRIVE = 0, 1, 2


@njit(cache=True)
def wrap_angle(angle_rad: float) -> float:
    """``dukw_common.geometry.wrap_angle`` (Python's float modulo: the same bits)."""
    return (angle_rad + math.pi) % (2.0 * math.pi) - math.pi


@njit(cache=True)
def predict(x: np.ndarray, P: np.ndarray, q_rate: np.ndarray, dt: float, mode: int,
            in0: float, in1: float, in2: float, seaward_yaw_rad: float, inv_cos_slope: float,
            wave_omega_rps: float, wave_damping: float, gps_bias_tau_s: float,
            accel_bias_tau_s: float, heave_accel: float) -> None:
    """``MotionEkf.predict`` in place: x advanced by ``dt``, P = F P F^T + diag(q_rate) dt.

    ``mode`` ACCEL: (in0, in1) the body accelerations; DRIVE: (in0, in1, in2) the target's
    surge, yaw rate and time constant; HOLD: u, v, r held (random walk). ``heave_accel``:
    base_link's vertical acceleration (the IMU's), the heave rate's input; NaN: held."""
    n = x.shape[0]
    yaw, u, v, r = x[_YAW], x[_U], x[_V], x[_R]
    eta, eta_rate, abx, aby = x[_ETA], x[_ETA_RATE], x[_ABX], x[_ABY]
    c, s = math.cos(yaw), math.sin(yaw)
    rel = yaw - seaward_yaw_rad
    cr, sr = math.cos(rel), math.sin(rel)
    inv_cos = inv_cos_slope
    F = np.eye(n)
    x[_X] += (u * c - v * s) * dt
    x[_Y] += (u * s + v * c) * dt
    F[_X, _YAW] = (-u * s - v * c) * dt
    F[_X, _U] = c * dt
    F[_X, _V] = -s * dt
    F[_Y, _YAW] = (u * c - v * s) * dt
    F[_Y, _U] = s * dt
    F[_Y, _V] = c * dt
    x[_S] += (u * cr - v * sr) * inv_cos * dt
    F[_S, _YAW] = (-u * sr - v * cr) * inv_cos * dt
    F[_S, _U] = cr * inv_cos * dt
    F[_S, _V] = -sr * inv_cos * dt
    x[_YAW] = wrap_angle(yaw + r * dt)
    F[_YAW, _R] = dt
    if mode == ACCEL:
        x[_U] = u + (in0 - abx) * dt
        x[_V] = v + (in1 - aby) * dt
        F[_U, _ABX] = -dt
        F[_V, _ABY] = -dt
    elif mode == DRIVE:
        k = min(dt / in2, 1.0)
        x[_U] = u + (in0 - u) * k
        x[_V] = v - v * k
        x[_R] = r + (in1 - r) * k
        F[_U, _U] = 1.0 - k
        F[_V, _V] = 1.0 - k
        F[_R, _R] = 1.0 - k
    w, z = wave_omega_rps, wave_damping
    x[_ETA] = eta + eta_rate * dt
    x[_ETA_RATE] = eta_rate + (-w * w * eta - 2.0 * z * w * eta_rate) * dt
    F[_ETA, _ETA_RATE] = dt
    F[_ETA_RATE, _ETA] = -w * w * dt
    F[_ETA_RATE, _ETA_RATE] = 1.0 - 2.0 * z * w * dt
    decay = 1.0 - dt / gps_bias_tau_s
    x[_GBE] *= decay
    x[_GBN] *= decay
    F[_GBE, _GBE] = decay
    F[_GBN, _GBN] = decay
    leak = 1.0 - dt / accel_bias_tau_s
    x[_ABX] = abx * leak
    x[_ABY] = aby * leak
    F[_ABX, _ABX] = leak
    F[_ABY, _ABY] = leak
    x[_HZ] += x[_HW] * dt
    F[_HZ, _HW] = dt
    if heave_accel == heave_accel:       # not NaN
        x[_HW] += heave_accel * dt
    _propagate(F, P)
    for i in range(n):
        P[i, i] += q_rate[i] * dt


@njit(cache=True)
def _propagate(F: np.ndarray, P: np.ndarray) -> None:
    """P = F P F^T in place over F's nonzeros only (F is the identity plus a few terms):
    each row's nonzero columns listed once, then both products run over them in ascending
    column order, the same additions in the same order as the dense loops (the same bits),
    without the n^3 tests for zeros that were most of a prediction's cost (issue 16)."""
    n = P.shape[0]
    columns = np.empty((n, n), dtype=np.int64)
    counts = np.zeros(n, dtype=np.int64)
    for i in range(n):
        for k in range(n):
            if F[i, k] != 0.0:
                columns[i, counts[i]] = k
                counts[i] += 1
    FP = np.zeros((n, n))
    for i in range(n):
        for m in range(counts[i]):
            k = columns[i, m]
            f = F[i, k]
            for j in range(n):
                FP[i, j] += f * P[k, j]
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for m in range(counts[j]):
                k = columns[j, m]
                acc += FP[i, k] * F[j, k]
            P[i, j] = acc


@njit(cache=True)
def update_scalar(x: np.ndarray, P: np.ndarray, y: float, h: np.ndarray, var: float,
                  gate: float, masked: bool, only: np.ndarray) -> bool:
    """``MotionEkf.update_scalar`` in place for the innovation ``y``; False: gated out.

    ``masked``: the gain is restricted to ``only`` (0/1 per state) and P follows the Joseph
    form for one row, valid for any gain; else the optimal gain's P - k (P h)^T."""
    n = x.shape[0]
    Ph = np.empty(n)
    for i in range(n):
        acc = 0.0
        for j in range(n):
            hj = h[j]
            if hj != 0.0:
                acc += P[i, j] * hj
        Ph[i] = acc
    s = var
    for i in range(n):
        if h[i] != 0.0:
            s += h[i] * Ph[i]
    if not s > 0.0 or y * y > gate * gate * s:
        return False
    k = Ph / s
    if masked:
        for i in range(n):
            k[i] *= only[i]
    for i in range(n):
        x[i] += k[i] * y
    if masked:
        # (I - k h) P (I - k h)^T + k var k^T = P - k Ph^T - Ph k^T + k k^T (h P h + var)
        for i in range(n):
            for j in range(n):
                P[i, j] = P[i, j] - k[i] * Ph[j] - Ph[i] * k[j] + k[i] * k[j] * s
    else:
        for i in range(n):
            for j in range(n):
                P[i, j] -= k[i] * Ph[j]
    x[_YAW] = wrap_angle(x[_YAW])
    return True


@njit(cache=True)
def update_rows_2d(x: np.ndarray, P: np.ndarray, y0: float, y1: float, H: np.ndarray,
                   var0: float, var1: float, gate: float) -> bool:
    """``MotionEkf.update`` of a 2-D measurement with a diagonal R (variances ``var0``,
    ``var1``) in place for the innovation (y0, y1); False: gated out. The whole vector is
    gated on its Mahalanobis distance (S = H P H^T + R inverted in closed form; a singular S
    is rejected), then the two rows are applied in turn, the second's residual moved with
    the state the first corrected."""
    n = x.shape[0]
    ph0 = np.zeros(n)
    ph1 = np.zeros(n)
    for i in range(n):
        for j in range(n):
            ph0[i] += P[i, j] * H[0, j]
            ph1[i] += P[i, j] * H[1, j]
    a, b, c, d = var0, 0.0, 0.0, var1
    for i in range(n):
        a += H[0, i] * ph0[i]
        b += H[0, i] * ph1[i]
        c += H[1, i] * ph0[i]
        d += H[1, i] * ph1[i]
    det = a * d - b * c
    if det == 0.0:
        return False
    d2 = (y0 * (d * y0 - b * y1) + y1 * (a * y1 - c * y0)) / det
    if not math.isfinite(d2) or d2 > gate * gate:
        return False
    x_start = x.copy()
    update_scalar(x, P, y0, H[0], var0, math.inf, False, x_start)
    moved = 0.0
    for i in range(n):
        moved += H[1, i] * (x[i] - x_start[i])
    update_scalar(x, P, y1 - moved, H[1], var1, math.inf, False, x_start)
    return True


def warm(n_states: int = len(Idx)) -> None:
    """Compile (or load) every kernel for the argument types the filter passes, so that the
    first sample of a process does not (``make setup`` runs this once per build: the cache
    beside the module then serves every later process)."""
    x, P, ones = np.zeros(n_states), np.eye(n_states), np.ones(n_states)
    predict(x, P, ones, 0.01, HOLD, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.1, 1.0, 1.0, 0.0)
    h = np.zeros(n_states)
    h[_R] = 1.0
    update_scalar(x, P, 0.0, h, 1.0, math.inf, False, ones)
    h.flags.writeable = False            # the filter's constant rows are read-only
    update_scalar(x, P, 0.0, h, 1.0, math.inf, False, ones)
    H = np.zeros((2, n_states))
    H[0, _X] = H[1, _Y] = 1.0
    update_rows_2d(x, P, 0.0, 0.0, H, 1.0, 1.0, math.inf)
