"""The motion filter: a 17-state EKF in the plane, with the waterline distance, the wave, the
soil's strength, the accelerometers' gravity leak and the hull's heave.

State (``Idx``): odom position x, y; yaw; body surge u, sway v; yaw rate r; gyro-z bias;
waterline distance s (along the slope, base_link seaward of the mean waterline); wave
elevation eta at the vehicle and its rate (a noise-driven damped oscillator at the sea's
peak frequency); the DGPS position error east/north (first-order Gauss-Markov), so that
its slow drift is not taken for motion; the soil's strength against the contact model's soil
(a factor on the track forces' Wong model, 1 = that soil; a random walk), so that a beach
weaker or stronger than the soil the estimator knows is not read as water: the wave is a
zero-mean oscillation about the surveyed waterline, the soil lasts (issue 18); and the
surge and sway accelerations' slow error (first-order Gauss-Markov): gravity leaking through
the IMU's attitude error (0.2 deg x g = 0.034 m/s^2 for ~10 s), which the velocity would
otherwise integrate into a ground-speed bias of a few cm/s (issue 18: the slip at low belt
speeds); and the height of base_link (the keel, the tracks' bottom) above the mean water level
and its rate, driven by the IMU's vertical acceleration: on the sand it is the beach's height
under base_link, afloat the keel sits under the wave by the draft the hull's heave dynamics
give, so the heave carries the wave from the sand into the water and back (issue 18: the
surface at a touchdown in the surf).

Predict and update are the compiled kernels of ``ekf_kernels`` rather than filterpy's
generic ``ExtendedKalmanFilter``: its update cannot gate an innovation before applying it
and copies the state several times per call; a predict + scalar update is ~3 us
(benchmarks/bench_ekf.py). The track-force smoother does use filterpy.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

import numpy as np

from dukw_common.geometry import wrap_angle
from dukw_estimation import ekf_kernels as kernels
from dukw_estimation.ekf_states import N_STATES, Idx


# plain int for the hot path (indexing numpy with IntEnum members is slower)
_YAW = int(Idx.YAW)
#: The states the water-contact and track-force measurements may correct (the soil through
#: its correlation with the surface: both explain one force).
SURFACE_STATES = np.array([1.0 if i in (Idx.S, Idx.ETA, Idx.ETA_RATE, Idx.SOIL) else 0.0
                           for i in Idx])
#: The surface without the soil: a force update where the tracks carry little weight (the
#: force's product of factor and weight is then far from linear in either).
WATER_SURFACE_STATES = np.array([1.0 if i in (Idx.S, Idx.ETA, Idx.ETA_RATE) else 0.0
                                 for i in Idx])
#: A sounding afloat mixes the wave with the vehicle's heave: it may correct s only.
WATERLINE_STATE = np.array([1.0 if i == Idx.S else 0.0 for i in Idx])
#: ``heave.HeaveObserver``'s measurements: afloat the keel under the wave by the dynamic
#: draft moves the wave and the heave; the keel on the beach at a touchdown moves them and
#: the waterline distance (``HEAVE_SURFACE_STATES``), on the sand after it the heave only.
HEAVE_SURFACE_STATES = np.array([1.0 if i in (Idx.S, Idx.ETA, Idx.ETA_RATE, Idx.HEAVE,
                                              Idx.HEAVE_RATE) else 0.0 for i in Idx])
WAVE_HEAVE_STATES = np.array([1.0 if i in (Idx.ETA, Idx.ETA_RATE, Idx.HEAVE, Idx.HEAVE_RATE)
                              else 0.0 for i in Idx])
HEAVE_STATES = np.array([1.0 if i in (Idx.HEAVE, Idx.HEAVE_RATE) else 0.0 for i in Idx])
#: ``update_scalar`` without a mask (the kernel's argument when ``only`` is None)
_NO_MASK = np.ones(N_STATES)


class Outcome(Enum):
    """What became of one measurement."""

    ACCEPTED = 'accepted'
    REJECTED_NAN = 'rejected_nan'
    REJECTED_OUT_OF_ORDER = 'rejected_out_of_order'
    REJECTED_OUTLIER = 'rejected_outlier'
    IGNORED = 'ignored'          # disabled sensor, no fix, nothing to learn


@dataclass(frozen=True)
class ProcessNoise:
    """Continuous-time process noise densities (sigma per sqrt(s)) and the wave model."""

    position_m: float
    yaw_rad: float
    accel_mps2: float
    yaw_accel_rps2: float
    gyro_bias_rps: float
    waterline_m: float
    wave_omega_rps: float
    wave_damping: float
    wave_sigma_m: float
    gps_bias_sigma_m: float = 0.0
    gps_bias_tau_s: float = 1.0
    soil_scale_per_sqrt_s: float = 0.0
    accel_bias_sigma_mps2: float = 0.0
    accel_bias_tau_s: float = 1.0
    heave_accel_mps2: float = 0.0

    def wave_drive(self) -> float:
        """Spectral density driving the oscillator so that its stationary sigma is wave_sigma."""
        w = self.wave_omega_rps
        return 4.0 * self.wave_damping * w ** 3 * self.wave_sigma_m ** 2


class MotionEkf:
    """Planar EKF with gated updates. Angles in rad, SI units, odom ENU."""

    def __init__(self, x0: np.ndarray, p0_diag: np.ndarray, noise: ProcessNoise,
                 seaward_yaw_rad: float) -> None:
        self.x = np.asarray(x0, dtype=float).copy()
        self.P = np.diag(np.asarray(p0_diag, dtype=float))
        self.noise = noise
        self.seaward_yaw_rad = seaward_yaw_rad
        self._eye = np.eye(N_STATES)
        # process noise variance rates (diagonal of Q / dt) by acceleration noise: the noise
        # is frozen, and the predictions use one or two acceleration noises
        self._q_rates: dict[float, np.ndarray] = {}
        # the frozen noise's constants the prediction reads
        self._wave_omega_rps, self._wave_damping = noise.wave_omega_rps, noise.wave_damping
        self._gps_bias_tau_s = noise.gps_bias_tau_s
        self._accel_bias_tau_s = noise.accel_bias_tau_s
        self._accel_mps2 = noise.accel_mps2

    def predict(self, dt: float, accel_body: tuple[float, float] | None = None,
                drive_target: tuple[float, float, float] | None = None,
                accel_noise_mps2: float | None = None, slope_rad: float = 0.0,
                heave_accel_mps2: float = math.nan) -> None:
        """Advance by ``dt`` s.

        ``accel_body``: (du/dt, dv/dt) from the IMU (gravity and centripetal removed) as
        input. Else ``drive_target`` (u, r, time constant) pulls u and r towards what the
        tracks or propellers command; else u, v, r are held (random walk).
        ``heave_accel_mps2``: base_link's vertical acceleration, the heave rate's input
        (NaN: the heave rate held).
        """
        if dt <= 0.0:
            return
        if accel_body is not None:
            mode, inputs = kernels.ACCEL, (accel_body[0], accel_body[1], 0.0)
        elif drive_target is not None:
            mode, inputs = kernels.DRIVE, drive_target
        else:
            mode, inputs = kernels.HOLD, (0.0, 0.0, 0.0)
        accel = self._accel_mps2 if accel_noise_mps2 is None else accel_noise_mps2
        q_rate = self._q_rates.get(accel)
        if q_rate is None:
            q_rate = self._q_rates[accel] = self._q_rate(accel)
        kernels.predict(self.x, self.P, q_rate, dt, mode, float(inputs[0]), float(inputs[1]),
                        float(inputs[2]), self.seaward_yaw_rad, 1.0 / math.cos(slope_rad),
                        self._wave_omega_rps, self._wave_damping, self._gps_bias_tau_s,
                        self._accel_bias_tau_s, float(heave_accel_mps2))

    def _q_rate(self, accel_mps2: float) -> np.ndarray:
        """The diagonal of the process noise per second with this acceleration noise."""
        n = self.noise
        bias_q = 2.0 * n.gps_bias_sigma_m ** 2 / n.gps_bias_tau_s
        accel_q = 2.0 * n.accel_bias_sigma_mps2 ** 2 / n.accel_bias_tau_s
        return np.array([n.position_m ** 2, n.position_m ** 2, n.yaw_rad ** 2, accel_mps2 ** 2,
                         accel_mps2 ** 2, n.yaw_accel_rps2 ** 2, n.gyro_bias_rps ** 2,
                         n.waterline_m ** 2, 0.0, n.wave_drive(), bias_q, bias_q,
                         n.soil_scale_per_sqrt_s ** 2, accel_q, accel_q, 0.0,
                         n.heave_accel_mps2 ** 2])

    def update(self, z: np.ndarray, hx: np.ndarray, H: np.ndarray, R: np.ndarray,
               gate: float, angle_rows: tuple[int, ...] = ()) -> Outcome:
        """Gated EKF update. The whole vector is gated on its Mahalanobis distance (rejected
        above ``gate``); with a diagonal R it is then applied row by row (exact, and cheaper
        than the matrix form; a 2-D one in one compiled call, ``ekf_kernels.update_rows_2d``),
        else in Joseph form."""
        y = np.asarray(z, dtype=float) - hx
        for row in angle_rows:
            y[row] = wrap_angle(y[row])
        if H.shape[0] == 2 and R[0, 1] == 0.0 and R[1, 0] == 0.0:    # the DGPS's, the tracks'
            accepted = kernels.update_rows_2d(self.x, self.P, float(y[0]), float(y[1]),
                                              np.ascontiguousarray(H, dtype=float),
                                              float(R[0, 0]), float(R[1, 1]), float(gate))
            return Outcome.ACCEPTED if accepted else Outcome.REJECTED_OUTLIER
        PHt = self.P @ H.T
        S = H @ PHt + R
        try:
            S_inv = np.linalg.inv(S)
        except np.linalg.LinAlgError:
            return Outcome.REJECTED_OUTLIER
        d2 = float(y @ S_inv @ y)
        if not math.isfinite(d2) or d2 > gate * gate:
            return Outcome.REJECTED_OUTLIER
        if not np.count_nonzero(R - np.diag(np.diag(R))):
            x_start = self.x.copy()
            for row in range(H.shape[0]):
                # a later row's residual moves with the state the earlier rows corrected
                residual = y[row] - float(H[row] @ (self.x - x_start))
                self.update_scalar(residual, 0.0, H[row], float(R[row, row]), math.inf)
            return Outcome.ACCEPTED
        K = PHt @ S_inv
        self.x += K @ y
        self.x[_YAW] = wrap_angle(self.x[_YAW])
        I_KH = self._eye - K @ H
        self.P = I_KH @ self.P @ I_KH.T + K @ R @ K.T
        return Outcome.ACCEPTED

    def update_scalar(self, z: float, hx: float, h: np.ndarray, var: float,
                      gate: float, angle: bool = False,
                      only: np.ndarray | None = None) -> Outcome:
        """Gated update with one scalar measurement; ``h`` is the Jacobian row.

        ``only`` (a 0/1 mask) restricts the correction to some states (a Schmidt / consider
        update): the water-contact and depth models may move the waterline distance and the
        wave but must not push the motion states through their correlations.
        """
        y = z - hx
        if angle:
            y = wrap_angle(y)
        masked = only is not None
        accepted = kernels.update_scalar(self.x, self.P, float(y), h, float(var), float(gate),
                                         masked, only if masked else _NO_MASK)
        return Outcome.ACCEPTED if accepted else Outcome.REJECTED_OUTLIER

    def set_pose(self, x_m: float, y_m: float, yaw_rad: float, sigma_pos_m: float,
                 sigma_yaw_rad: float) -> None:
        """Reset the pose (and its covariance, decorrelated from the rest)."""
        for i, value, sigma in ((Idx.X, x_m, sigma_pos_m), (Idx.Y, y_m, sigma_pos_m),
                                (Idx.YAW, wrap_angle(yaw_rad), sigma_yaw_rad)):
            self.x[i] = value
            self.P[i, :] = 0.0
            self.P[:, i] = 0.0
            self.P[i, i] = sigma * sigma
