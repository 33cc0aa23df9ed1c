"""The motion filter: the motion sensors' models around the EKF (``ekf.MotionEkf``), ROS-free.

It keeps the latest motion inputs (IMU, track and propeller status), the sensors' last
times, the GPS datum, and predicts the EKF forward: with the IMU's accelerations, else
with the drive model (tracks when their share of the weight drives the vehicle, else the
propellers). It corrects heading, yaw rate and gyro bias from the IMU, the position and
velocity from the DGPS (antenna lever arm), GPS velocity stale on land, the speed
from the tracks, the heave rate from the DGPS's up velocity, and at rest the zero velocity
(``zero_velocity``). The surface states'
corrections live in ``surface.SurfaceObserver``.
"""
from __future__ import annotations

import math

import numpy as np

from dukw_common.geometry import local_enu_from_geodetic, wrap_angle
from dukw_common.vehicle import Vehicle
from dukw_model import traction
from dukw_model.lever_arm import (base_from_sensor_point, lever_arm_enu,
                                  sensor_point_velocity_body, specific_force_at_base)
from dukw_estimation.ekf import HEAVE_STATES, N_STATES, Idx, MotionEkf, Outcome, ProcessNoise
from dukw_common.readings import DriveStatus, GpsFix, GpsVelocity, ImuSample
from dukw_estimation.samples import OdometryEstimate
from dukw_estimation.settings import SENSORS, EkfSettings

MAX_PREDICT_STEP_S = 0.02
GROUNDED_FRACTION = 0.5          # above this weight share the tracks drive the vehicle
#: below this belt speed the slip's denominator is held (``traction.slip``): the slip then
#: no longer says the ground speed
TRACK_ODOMETRY_MIN_BELT_MPS = traction.MIN_TRACK_SPEED_MPS


#: the odometry covariances (REP 105 order x y z roll pitch yaw / vx vy vz wx wy wz): what the
#: filter does not estimate is fixed; the rest is copied from P with precomputed indices
_POSE_COV_BASE = np.diag([0.0, 0.0, 1e3, 1e-2, 1e-2, 0.0])
_TWIST_COV_BASE = np.diag([0.0, 0.0, 1e3, 1e3, 1e3, 0.0])
#: (row, column in the message's covariance, row, column in P): x, y, yaw -> x, y, yaw;
#: u, v -> vx, vy; r -> wz (no u, v - r terms). Element by element: fancy indexing costs
#: more than these few items
_POSE_MAP = ((0, Idx.X), (1, Idx.Y), (5, Idx.YAW))
_TWIST_MAP = ((0, Idx.U), (1, Idx.V))
_POSE_COPY = tuple((a, b, int(i), int(j)) for a, i in _POSE_MAP for b, j in _POSE_MAP)
_TWIST_COPY = tuple((a, b, int(i), int(j)) for a, i in _TWIST_MAP
                    for b, j in _TWIST_MAP) + ((5, 5, int(Idx.R), int(Idx.R)),)
_X, _Y, _YAW, _U, _V, _R, _S = (int(Idx.X), int(Idx.Y), int(Idx.YAW), int(Idx.U), int(Idx.V),
                                int(Idx.R), int(Idx.S))
_BIAS = int(Idx.BIAS)
#: the IMU's measurement rows (read only): the gyro's z rate r + bias, the heading yaw
_H_GYRO = np.zeros(N_STATES)
_H_GYRO[[_R, _BIAS]] = 1.0
_H_GYRO.flags.writeable = False
_H_YAW = np.zeros(N_STATES)
_H_YAW[_YAW] = 1.0
_H_YAW.flags.writeable = False
#: the zero-velocity update's rows (read only): surge u, sway v
_H_REST = np.zeros((2, N_STATES))
_H_REST[0, _U] = _H_REST[1, _V] = 1.0
_H_REST.flags.writeable = False
#: the GPS up velocity's row (read only): the heave rate
_HEAVE_RATE = int(Idx.HEAVE_RATE)
_H_HEAVE_RATE = np.zeros(N_STATES)
_H_HEAVE_RATE[_HEAVE_RATE] = 1.0
_H_HEAVE_RATE.flags.writeable = False

#: floor of cos(roll) cos(pitch) when the body-z specific force is turned vertical (60 deg:
#: far beyond the vehicle's attitudes, vehicle.md 3: 19 deg the steepest slope tested)
MIN_TILT_COS = 0.5

class MotionFilter:
    """Pose, twist, gyro bias and GPS bias of base_link in odom (and the EKF's time)."""

    def __init__(self, vehicle: Vehicle, settings: EkfSettings) -> None:
        self.vehicle = vehicle
        self.settings = settings
        self.reset()

    def reset(self) -> None:
        """Back to the initial covariance, no sample seen."""
        st = self.settings
        p0 = np.array([st.init_position_m ** 2, st.init_position_m ** 2, st.init_yaw_rad ** 2,
                       st.init_velocity_mps ** 2, st.init_velocity_mps ** 2,
                       st.init_yaw_rate_rps ** 2, st.init_gyro_bias_rps ** 2,
                       st.waterline_sigma_m ** 2, st.wave_sigma_m ** 2 + 1e-6,
                       (st.wave_sigma_m * 2 * math.pi * st.wave_peak_frequency_hz) ** 2 + 1e-6,
                       st.gps_bias_sigma_m ** 2, st.gps_bias_sigma_m ** 2,
                       st.soil_scale_sigma ** 2, st.q_accel_bias_mps2 ** 2,
                       st.q_accel_bias_mps2 ** 2, st.init_heave_m ** 2,
                       st.init_heave_rate_mps ** 2])
        noise = ProcessNoise(st.q_position_m, st.q_yaw_rad, st.q_accel_mps2, st.q_yaw_accel_rps2,
                             st.q_gyro_bias_rps, st.q_waterline_m,
                             2 * math.pi * st.wave_peak_frequency_hz, st.wave_damping_ratio,
                             st.wave_sigma_m, st.gps_bias_sigma_m, st.gps_bias_tau_s,
                             st.soil_scale_process_per_sqrt_s if st.soil_scale_sigma > 0.0
                             else 0.0,         # sigma 0: the soil trusted, the factor 1
                             st.q_accel_bias_mps2, st.q_accel_bias_tau_s, st.q_heave_accel_mps2)
        x0 = np.zeros(N_STATES)
        x0[Idx.SOIL] = 1.0               # the soil as the contact model knows it
        self.ekf = MotionEkf(x0, p0, noise, st.seaward_yaw_rad)
        self.t_s: float | None = None
        self.last_t = {s: -math.inf for s in SENSORS}
        self.datum: tuple[float, float, float] | None = None
        if not st.datum_from_first_fix:
            self.datum = (st.datum_latitude_deg, st.datum_longitude_deg, st.datum_altitude_m)
        self.position_set = False
        self.yaw_set = False
        self.imu: ImuSample | None = None
        self.accel_base = (math.nan, math.nan, math.nan)   # specific force at base_link
        # of the last IMU sample, worked out once when it came (read at every prediction
        # step and contact decision): ``heave_accel_mps2``, ``gravity_free_accel``
        self._heave_accel_mps2 = math.nan
        self._gravity_free_mps2 = (math.nan, math.nan)
        self.tracks: DriveStatus | None = None
        self.props: DriveStatus | None = None
        self.track_odometry_t_s = -math.inf     # the last held-slip speed update

    def fresh(self, sensor: str, t_s: float) -> bool:
        """The sensor spoke within ``sensor_timeout_s`` before ``t_s``."""
        return t_s - self.last_t[sensor] <= self.settings.sensor_timeout_s

    def fresh_now(self, sensor: str) -> bool:
        """The sensor is fresh at the filter's time (False before any sample)."""
        return self.t_s is not None and self.fresh(sensor, self.t_s)

    # ------------------------------------------------------------------ pose
    def set_pose(self, x_m: float, y_m: float, yaw_rad: float) -> None:
        """Reset the pose in odom; the waterline distance follows the new position."""
        self.ekf.set_pose(x_m, y_m, yaw_rad, self.settings.init_position_m,
                          self.settings.init_yaw_rad)
        self._init_waterline()
        self.position_set = self.yaw_set = True

    def _init_waterline(self) -> None:
        st = self.settings
        x = self.ekf.x
        seaward = ((x[Idx.X] - st.waterline_x_m) * math.cos(st.seaward_yaw_rad)
                   + (x[Idx.Y] - st.waterline_y_m) * math.sin(st.seaward_yaw_rad))
        inv_cos = 1.0 / math.cos(self.vehicle.site.beach_slope_rad)
        x[Idx.S] = seaward * inv_cos
        # s is the seaward position along the slope plus the waterline's survey error: it is
        # correlated with x, y as they are, so the GPS's later corrections of the position
        # (its drift averaged out) move s too
        j = np.zeros(N_STATES)
        j[Idx.X] = math.cos(st.seaward_yaw_rad) * inv_cos
        j[Idx.Y] = math.sin(st.seaward_yaw_rad) * inv_cos
        P = self.ekf.P
        cross = P @ j
        cross[Idx.S] = 0.0
        P[Idx.S, :] = cross
        P[:, Idx.S] = cross
        P[Idx.S, Idx.S] = float(j @ cross) + st.waterline_sigma_m ** 2

    # ------------------------------------------------------------------ time
    def predict_to(self, t_s: float, fraction: float) -> None:
        """Predict to ``t_s`` in steps of at most MAX_PREDICT_STEP_S (no-op when not newer);
        ``fraction`` is the weight share on the tracks (for the drive model)."""
        if self.t_s is None:
            self.t_s = t_s
            return
        while t_s > self.t_s:
            dt = min(MAX_PREDICT_STEP_S, t_s - self.t_s)
            self._predict(dt, fraction)
            self.t_s += dt

    def _predict(self, dt: float, fraction: float) -> None:
        x = self.ekf.x
        st = self.settings
        now = self.t_s + dt
        imu = self.imu
        accel = None
        noise = None
        target = None
        heave = math.nan
        if imu is not None and self.fresh('imu', now) and math.isfinite(self.accel_base[0]):
            ax, ay = self.gravity_free_accel()
            accel = (ax + x[Idx.R] * x[Idx.V], ay - x[Idx.R] * x[Idx.U])
            heave = self.heave_accel_mps2()
        else:
            noise = st.q_accel_no_imu_mps2
            target = self._drive_target(now, fraction)
        self.ekf.predict(dt, accel, target, noise, self.vehicle.site.beach_slope_rad, heave)

    def heave_accel_mps2(self) -> float:
        """Vertical acceleration of base_link, m/s^2: the last IMU sample's specific force at
        base_link over the tilt, less g (NaN without an IMU sample)."""
        return self._heave_accel_mps2

    def gravity_free_accel(self) -> tuple[float, float]:
        """The last IMU sample's surge and sway acceleration at base_link, m/s^2, gravity
        removed with its attitude (NaN without a sample with accelerations): gravity along
        the body axes from the attitude, scaled by the measured vertical specific force
        (heave accelerations afloat): g_up = f_z / (cos roll cos pitch)."""
        return self._gravity_free_mps2

    def _imu_accelerations(self) -> None:
        """``heave_accel_mps2`` and ``gravity_free_accel`` of the sample just taken."""
        imu = self.imu
        fx, fy, fz = self.accel_base
        g_up = _vertical_specific_force(imu, fz)
        self._heave_accel_mps2 = g_up - self.vehicle.body.gravity_mps2 \
            if math.isfinite(fz) else math.nan
        self._gravity_free_mps2 = (fx + g_up * math.sin(imu.pitch_rad),
                                   fy - g_up * math.sin(imu.roll_rad) * math.cos(imu.pitch_rad))

    def _drive_target(self, now: float, fraction: float) -> tuple[float, float, float] | None:
        st = self.settings
        tau = st.drive_time_constant_s
        if fraction > GROUNDED_FRACTION and self.tracks is not None \
                and self.fresh('tracks', now):
            vp, vs = self.tracks.port.speed_mps, self.tracks.stbd.speed_mps
            return 0.5 * (vp + vs), (vs - vp) / st.effective_track_width_m, tau
        if self.props is not None and self.fresh('props', now):
            thrust = self.props.port.force_n + self.props.stbd.force_n
            speed = math.copysign(math.sqrt(abs(thrust) / st.water_drag_n_per_mps2), thrust)
            return speed, float(self.ekf.x[Idx.R]), tau
        return None

    # ------------------------------------------------------------------ IMU
    def add_imu(self, s: ImuSample) -> tuple[Outcome, float]:
        """Yaw rate and bias, heading; keeps the sample and its specific force at base_link.
        Returns the outcome and the time since the previous IMU sample."""
        dt = s.t_s - self.imu.t_s if self.imu is not None else 0.0
        self.accel_base = self._accel_at_base_link(s, dt)
        self.imu = s
        self._imu_accelerations()
        st = self.settings
        var = s.yaw_rate_var_rps2 if s.yaw_rate_var_rps2 > 0 else st.gyro_rps ** 2
        x = self.ekf.x
        out = self.ekf.update_scalar(s.yaw_rate_rps, x[_R] + x[_BIAS], _H_GYRO, var,
                                     st.gate_imu)
        if math.isfinite(s.yaw_rad):
            if not self.yaw_set:
                self.ekf.x[Idx.YAW] = wrap_angle(s.yaw_rad)
                self.yaw_set = True
            var = s.yaw_var_rad2 if s.yaw_var_rad2 > 0 else st.yaw_rad ** 2
            yaw_out = self.ekf.update_scalar(s.yaw_rad, self.ekf.x[_YAW], _H_YAW, var,
                                             st.gate_imu, angle=True)
            if yaw_out is not Outcome.ACCEPTED:
                out = yaw_out
        return out, dt

    def _accel_at_base_link(self, s: ImuSample, dt: float) -> tuple[float, float, float]:
        """The specific force moved from the IMU (sensors.imu_z_m above base_link) to base_link.

        A point at r = (0, 0, h) feels alpha x r + w x (w x r) more than base_link; alpha comes
        from differencing the gyro (roll and pitch rates), which matters afloat.
        """
        h = self.vehicle.sensors.imu_z_m
        prev = self.imu
        if prev is not None and 0.0 < dt <= MAX_PREDICT_STEP_S * 5:
            alpha_x = (s.roll_rate_rps - prev.roll_rate_rps) / dt
            alpha_y = (s.pitch_rate_rps - prev.pitch_rate_rps) / dt
        else:
            alpha_x = alpha_y = 0.0
        return specific_force_at_base((s.accel_x_mps2, s.accel_y_mps2, s.accel_z_mps2),
                                      (s.roll_rate_rps, s.pitch_rate_rps, s.yaw_rate_rps),
                                      (alpha_x, alpha_y), h)


    def _mast_attitude(self) -> tuple[float, float, float, float]:
        """(roll, pitch, roll rate, pitch rate) of the last IMU sample for the antenna's lever
        arm (level and still without one)."""
        imu = self.imu
        if imu is None:
            return 0.0, 0.0, 0.0, 0.0
        return imu.roll_rad, imu.pitch_rad, imu.roll_rate_rps, imu.pitch_rate_rps


    # ------------------------------------------------------------------ DGPS
    def add_gps_fix(self, s: GpsFix) -> Outcome:
        """DGPS position (geodetic) -> local ENU at the datum; corrects x, y."""
        if self.datum is None:
            self.datum = (s.latitude_deg, s.longitude_deg, s.altitude_m)
        east, north, _ = local_enu_from_geodetic(s.latitude_deg, s.longitude_deg, s.altitude_m,
                                                 *self.datum)
        x = self.ekf.x
        roll, pitch, _, _ = self._mast_attitude()
        h = self.vehicle.sensors.gps_antenna_z_m
        offset = np.array(lever_arm_enu(roll, pitch, x[Idx.YAW], h)[:2])
        var = s.horizontal_var_m2 if s.horizontal_var_m2 > 0 and self.settings.gps_bias_sigma_m \
            == 0.0 else self.settings.gps_position_m ** 2
        if not self.position_set:      # the first fix: start there, as sure as the fix is
            x[Idx.X], x[Idx.Y], _ = base_from_sensor_point((east, north, 0.0), roll, pitch,
                                                            x[Idx.YAW], h)
            for i in (Idx.X, Idx.Y):
                self.ekf.P[i, :] = 0.0
                self.ekf.P[:, i] = 0.0
                self.ekf.P[i, i] = var + self.settings.gps_bias_sigma_m ** 2
            self._init_waterline()
            self.position_set = True
        H = np.zeros((2, N_STATES))
        H[0, Idx.X] = H[1, Idx.Y] = H[0, Idx.GPS_BIAS_E] = H[1, Idx.GPS_BIAS_N] = 1.0
        H[0, Idx.YAW], H[1, Idx.YAW] = -offset[1], offset[0]    # d(offset)/d(yaw)
        # (with bias states the message's covariance, the total error, is not the white part)
        predicted = x[[Idx.X, Idx.Y]] + offset + x[[Idx.GPS_BIAS_E, Idx.GPS_BIAS_N]]
        return self.ekf.update(np.array([east, north]), predicted, H, np.eye(2) * var,
                               self.settings.gate_gps_fix)

    def add_gps_velocity(self, s: GpsVelocity) -> Outcome:
        """DGPS ground velocity of the antenna (ENU); corrects u, v and yaw."""
        x = self.ekf.x
        h = self.vehicle.sensors.gps_antenna_z_m
        _, _, p, q = self._mast_attitude()
        ub, vb = sensor_point_velocity_body(x[Idx.U], x[Idx.V], p, q, h)
        c, sn = math.cos(x[Idx.YAW]), math.sin(x[Idx.YAW])
        H = np.zeros((2, N_STATES))
        H[0, Idx.U], H[0, Idx.V], H[0, Idx.YAW] = c, -sn, -sn * ub - c * vb
        H[1, Idx.U], H[1, Idx.V], H[1, Idx.YAW] = sn, c, c * ub - sn * vb
        var = s.var_mps2 if s.var_mps2 > 0 else self.settings.gps_velocity_mps ** 2
        out = self.ekf.update(np.array([s.east_mps, s.north_mps]),
                              np.array([c * ub - sn * vb, sn * ub + c * vb]), H,
                              np.eye(2) * var, self.settings.gate_gps_vel)
        if math.isfinite(s.up_mps):
            # the antenna's up velocity is base_link's heave rate (the mast's rotation moves
            # it up only to second order in roll and pitch); it corrects the heave only: on the
            # sand the keel's height is tied to the waterline distance through the estimated
            # slope, which need not be the beach's
            var = s.up_var_mps2 if s.up_var_mps2 > 0 else self.settings.gps_velocity_mps ** 2
            up = self.ekf.update_scalar(s.up_mps, float(self.ekf.x[_HEAVE_RATE]),
                                        _H_HEAVE_RATE, var, self.settings.gate_gps_vel,
                                        only=HEAVE_STATES)
            if out is Outcome.ACCEPTED:
                out = up
        return out

    # ------------------------------------------------------------------ tracks
    def track_odometry(self, s: DriveStatus, slips: tuple[float, float] | None) -> None:
        """GPS velocity stale on land: the tracks say roughly how fast we go, at the slips
        ``slips`` (port, starboard) they ran at when the GPS velocity was last fresh. On
        sand the tracks never grip: the Wong force needs slip, 0.1-0.6 on the campaign's
        dry beach, 1 for a vehicle stuck in the surf, so the belt speed alone overstates
        the ground speed by slip x belt speed (issue 18: a stuck vehicle read as moving at
        its belt speed through a GPS dropout). The soil and the load last over a dropout
        of seconds; the waves' change of the slip is in ``noise.track_odometry_mps``. The
        held slips' error is one for the whole dropout (the slip's change since), so the
        tracks speak at most every ``noise.track_odometry_period_s``, not at each status.
        Nothing without a held slip, or with a belt too slow for the slip to say the
        ground speed (``TRACK_ODOMETRY_MIN_BELT_MPS``)."""
        st = self.settings
        speeds = (s.port.speed_mps, s.stbd.speed_mps)
        if slips is None or not all(math.isfinite(i) for i in slips) \
                or min(abs(v) for v in speeds) < TRACK_ODOMETRY_MIN_BELT_MPS \
                or s.t_s - self.track_odometry_t_s < st.track_odometry_period_s:
            return
        self.track_odometry_t_s = s.t_s
        port, stbd = (v * (1.0 - i) for v, i in zip(speeds, slips, strict=True))
        H = np.zeros((2, N_STATES))
        H[0, Idx.U] = H[1, Idx.R] = 1.0
        z = np.array([0.5 * (port + stbd), (stbd - port) / st.effective_track_width_m])
        var = st.track_odometry_mps ** 2
        R = np.diag([var, var / st.effective_track_width_m ** 2])
        self.ekf.update(z, self.ekf.x[[Idx.U, Idx.R]], H, R, math.inf)

    # ------------------------------------------------------------------ at rest
    def zero_velocity(self, sigma_mps: float, gate: float) -> Outcome:
        """The vehicle at rest: surge and sway measured as 0 with ``sigma_mps``, one
        hypothesis gated as one: (u, v) on their joint Mahalanobis distance (2 degrees of
        freedom), so a slide the velocity shows rejects the rest whole."""
        var = sigma_mps * sigma_mps
        x = self.ekf.x
        return self.ekf.update(np.zeros(2), np.array([x[_U], x[_V]]), _H_REST,
                               np.diag([var, var]), gate)

    # ------------------------------------------------------------------ output
    def odometry(self, slope_rad: float) -> OdometryEstimate:
        """Pose and twist of base_link in odom with covariances (z on the slope)."""
        x, P = self.ekf.x, self.ekf.P
        imu = self.imu
        roll = imu.roll_rad if imu else 0.0
        pitch = imu.pitch_rad if imu else 0.0
        pose_cov = _POSE_COV_BASE.copy()
        for a, b, i, j in _POSE_COPY:
            pose_cov[a, b] = P[i, j]
        twist_cov = _TWIST_COV_BASE.copy()
        for a, b, i, j in _TWIST_COPY:
            twist_cov[a, b] = P[i, j]
        x_m, y_m, yaw, u, v, r, _, s = x[:_S + 1].tolist()     # floats: the same values
        z = -s * math.sin(slope_rad)
        return OdometryEstimate(self.t_s or 0.0, x_m, y_m, z, roll, pitch, yaw, u, v, r,
                                pose_cov, twist_cov)


def _vertical_specific_force(imu, fz_mps2: float) -> float:
    """The specific force along the vertical from its body-z component and the attitude,
    f_z / (cos roll cos pitch), m/s^2; the tilt's cosine floored at MIN_TILT_COS."""
    tilt = math.cos(imu.roll_rad) * math.cos(imu.pitch_rad)
    return fz_mps2 / max(tilt, MIN_TILT_COS)
