"""The motion EKF's compiled kernels (ekf_kernels) against the textbook numpy forms: the same
filter to the rounding of the products' summation order (issue 16)."""
import math

import numpy as np
import pytest

from dukw_estimation.ekf import N_STATES, SURFACE_STATES, Idx, MotionEkf, Outcome, ProcessNoise

NOISE = ProcessNoise(0.01, 0.001, 0.3, 0.1, 1e-4, 0.01, 1.2, 0.1, 0.2, 0.5, 30.0, 0.01,
                     0.02, 10.0)
SEAWARD_RAD = 0.4
#: relative agreement of a covariance entry with the numpy form (summation order only)
REL = 1e-12


def random_filter(rng: np.random.Generator) -> MotionEkf:
    x = rng.standard_normal(N_STATES)
    A = rng.standard_normal((N_STATES, N_STATES)) * 0.1
    ekf = MotionEkf(x, np.ones(N_STATES), NOISE, SEAWARD_RAD)
    ekf.P = A @ A.T + np.eye(N_STATES) * 0.01
    return ekf


def reference_predict(x, P, dt, accel, target, slope_rad, q_diag, heave_accel=math.nan):
    """The numpy prediction the kernel replaced: F from the motion model, P = F P F^T + Q dt
    (and the heave: its height integrates its rate, the rate the vertical acceleration)."""
    x = x.copy()
    yaw, u, v, r = x[Idx.YAW], x[Idx.U], x[Idx.V], x[Idx.R]
    c, s = math.cos(yaw), math.sin(yaw)
    cr, sr = math.cos(yaw - SEAWARD_RAD), math.sin(yaw - SEAWARD_RAD)
    inv_cos = 1.0 / math.cos(slope_rad)
    F = np.eye(N_STATES)
    x[Idx.X] += (u * c - v * s) * dt
    x[Idx.Y] += (u * s + v * c) * dt
    F[Idx.X, [Idx.YAW, Idx.U, Idx.V]] = (-u * s - v * c) * dt, c * dt, -s * dt
    F[Idx.Y, [Idx.YAW, Idx.U, Idx.V]] = (u * c - v * s) * dt, s * dt, c * dt
    x[Idx.S] += (u * cr - v * sr) * inv_cos * dt
    F[Idx.S, [Idx.YAW, Idx.U, Idx.V]] = np.array([-u * sr - v * cr, cr, -sr]) * inv_cos * dt
    x[Idx.YAW] = (yaw + r * dt + math.pi) % (2 * math.pi) - math.pi
    F[Idx.YAW, Idx.R] = dt
    if accel is not None:
        x[Idx.U] += (accel[0] - x[Idx.ACCEL_BIAS_X]) * dt
        x[Idx.V] += (accel[1] - x[Idx.ACCEL_BIAS_Y]) * dt
        F[Idx.U, Idx.ACCEL_BIAS_X] = F[Idx.V, Idx.ACCEL_BIAS_Y] = -dt
    elif target is not None:
        k = min(dt / target[2], 1.0)
        x[Idx.U] += (target[0] - u) * k
        x[Idx.V] -= v * k
        x[Idx.R] += (target[1] - r) * k
        F[Idx.U, Idx.U] = F[Idx.V, Idx.V] = F[Idx.R, Idx.R] = 1.0 - k
    w, z = NOISE.wave_omega_rps, NOISE.wave_damping
    eta, eta_rate = x[Idx.ETA], x[Idx.ETA_RATE]
    x[Idx.ETA] = eta + eta_rate * dt
    x[Idx.ETA_RATE] = eta_rate + (-w * w * eta - 2 * z * w * eta_rate) * dt
    F[Idx.ETA, Idx.ETA_RATE] = dt
    F[Idx.ETA_RATE, Idx.ETA] = -w * w * dt
    F[Idx.ETA_RATE, Idx.ETA_RATE] = 1.0 - 2 * z * w * dt
    decay, leak = 1.0 - dt / NOISE.gps_bias_tau_s, 1.0 - dt / NOISE.accel_bias_tau_s
    for i, f in ((Idx.GPS_BIAS_E, decay), (Idx.GPS_BIAS_N, decay),
                 (Idx.ACCEL_BIAS_X, leak), (Idx.ACCEL_BIAS_Y, leak)):
        x[i] *= f
        F[i, i] = f
    x[Idx.HEAVE] += x[Idx.HEAVE_RATE] * dt
    F[Idx.HEAVE, Idx.HEAVE_RATE] = dt
    if not math.isnan(heave_accel):
        x[Idx.HEAVE_RATE] += heave_accel * dt
    return x, F @ P @ F.T + np.diag(q_diag) * dt


def assert_close(mine, reference):
    scale = np.maximum(np.abs(reference), 1e-300)
    assert np.all(np.abs(mine - reference) <= REL * np.maximum(scale, np.abs(reference).max()))


@pytest.mark.parametrize('inputs', ['accel', 'target', 'hold'])
def test_prediction_is_the_numpy_form(inputs):
    rng = np.random.default_rng(7)
    for _ in range(20):
        ekf = random_filter(rng)
        accel = tuple(rng.standard_normal(2)) if inputs == 'accel' else None
        target = (0.8, -0.1, 0.5) if inputs == 'target' else None
        noise = None if inputs == 'accel' else 0.7
        dt, slope = 0.013, 0.05
        heave = rng.standard_normal() if inputs == 'accel' else math.nan
        x_ref, P_ref = reference_predict(ekf.x, ekf.P, dt, accel, target, slope,
                                         ekf._q_rate(noise or NOISE.accel_mps2), heave)
        ekf.predict(dt, accel, target, noise, slope, heave)
        assert np.array_equal(ekf.x, x_ref)       # the state's arithmetic is the same
        assert_close(ekf.P, P_ref)


@pytest.mark.parametrize('masked', [False, True])
def test_scalar_update_is_the_numpy_form(masked):
    rng = np.random.default_rng(8)
    for _ in range(20):
        ekf = random_filter(rng)
        h = np.zeros(N_STATES)
        h[[Idx.S, Idx.ETA, Idx.YAW]] = rng.standard_normal(3)
        x0, P0 = ekf.x.copy(), ekf.P.copy()
        z, hx, var = 0.3, 0.1, 0.05
        only = SURFACE_STATES if masked else None
        assert ekf.update_scalar(z, hx, h, var, math.inf, only=only) is Outcome.ACCEPTED
        Ph = P0 @ h
        s = h @ Ph + var
        k = Ph / s * (only if masked else 1.0)
        x_ref = x0 + k * (z - hx)
        x_ref[Idx.YAW] = (x_ref[Idx.YAW] + math.pi) % (2 * math.pi) - math.pi
        I_kh = np.eye(N_STATES) - np.outer(k, h)
        P_ref = I_kh @ P0 @ I_kh.T + np.outer(k, k) * var      # Joseph form, any gain
        assert_close(ekf.x, x_ref)
        assert np.allclose(ekf.P, P_ref, rtol=1e-9, atol=1e-12)


def test_scalar_update_gates_an_outlier_and_changes_nothing():
    ekf = random_filter(np.random.default_rng(9))
    x0, P0 = ekf.x.copy(), ekf.P.copy()
    h = np.zeros(N_STATES)
    h[Idx.R] = 1.0
    s = P0[Idx.R, Idx.R] + 0.01
    assert ekf.update_scalar(3.1 * math.sqrt(s), 0.0, h, 0.01, 3.0) is Outcome.REJECTED_OUTLIER
    assert np.array_equal(ekf.x, x0) and np.array_equal(ekf.P, P0)
    assert ekf.update_scalar(2.9 * math.sqrt(s), 0.0, h, 0.01, 3.0) is Outcome.ACCEPTED


def test_two_row_update_is_the_joseph_form_of_the_whole_vector():
    rng = np.random.default_rng(10)
    for _ in range(20):
        ekf = random_filter(rng)
        H = np.zeros((2, N_STATES))
        H[0, [Idx.X, Idx.YAW, Idx.GPS_BIAS_E]] = 1.0, rng.standard_normal(), 1.0
        H[1, [Idx.Y, Idx.YAW, Idx.GPS_BIAS_N]] = 1.0, rng.standard_normal(), 1.0
        R = np.diag([0.04, 0.09])
        z, hx = rng.standard_normal(2) * 0.1, np.zeros(2)
        x0, P0 = ekf.x.copy(), ekf.P.copy()
        assert ekf.update(z, hx, H, R, math.inf) is Outcome.ACCEPTED
        S = H @ P0 @ H.T + R
        K = P0 @ H.T @ np.linalg.inv(S)
        x_ref = x0 + K @ (z - hx)
        x_ref[Idx.YAW] = (x_ref[Idx.YAW] + math.pi) % (2 * math.pi) - math.pi
        I_KH = np.eye(N_STATES) - K @ H
        P_ref = I_KH @ P0 @ I_KH.T + K @ R @ K.T
        assert np.allclose(ekf.x, x_ref, rtol=1e-9, atol=1e-12)
        assert np.allclose(ekf.P, P_ref, rtol=1e-9, atol=1e-12)


def test_two_row_update_gates_on_the_whole_vector():
    ekf = random_filter(np.random.default_rng(11))
    H = np.zeros((2, N_STATES))
    H[0, Idx.X] = H[1, Idx.Y] = 1.0
    R = np.diag([0.04, 0.04])
    S = H @ ekf.P @ H.T + R
    y = np.array([1.0, -1.0])
    d = math.sqrt(float(y @ np.linalg.inv(S) @ y))
    x0, P0 = ekf.x.copy(), ekf.P.copy()
    assert ekf.update(y, np.zeros(2), H, R, 0.99 * d) is Outcome.REJECTED_OUTLIER
    assert np.array_equal(ekf.x, x0) and np.array_equal(ekf.P, P0)
    assert ekf.update(y, np.zeros(2), H, R, 1.01 * d) is Outcome.ACCEPTED
