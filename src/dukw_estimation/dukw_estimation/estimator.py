"""The estimator: motion EKF + slip + hull submersion + track forces, ROS-free.

Feed it ``samples`` dataclasses in time order (``add_*``), ask for ``odometry()`` and
``traction()``. It rejects NaN, out-of-order and Mahalanobis-outlier measurements and
counts them per sensor; a sensor silent for ``sensor_timeout_s`` is reported stale and the
filter goes on predicting without it (robot_localization's behaviour).
"""
from __future__ import annotations

import math
from collections import defaultdict

import numpy as np

from dukw_common.diagnostics import Health, Level, RateCounter
from dukw_common.geometry import local_enu_from_geodetic, wrap_angle
from dukw_common.vehicle import SoilParams, Vehicle
from dukw_model import buoyancy, traction
from dukw_model.seakeeping import heave_constants
from dukw_model.lever_arm import (base_from_sensor_point, lever_arm_enu,
                                  sensor_point_velocity_body, specific_force_at_base)
from dukw_estimation.ekf import (N_STATES, SURFACE_STATES, WATERLINE_STATE, Idx, MotionEkf,
                                 Outcome, ProcessNoise)
from dukw_estimation.force_filter import ForceSmoother
from dukw_estimation.samples import (DepthReading, DriveStatus, GpsFix, GpsVelocity,
                                     ImuSample, OdometryEstimate, TractionEstimate,
                                     WaterContact)
from dukw_estimation.settings import SENSORS, EkfSettings

MAX_PREDICT_STEP_S = 0.02
GROUNDED_FRACTION = 0.5          # above this weight share the tracks drive the vehicle
SLOPE_FRACTION = 0.9             # above this share the pitch is the beach's, not the waves'
TOUCHDOWN_SHARE = 0.8           # afloat until the mean-surface volume drops below this share
FRACTION_PERIOD_S = 0.1          # how often the IMU path refreshes the weight share
SECANT_STEPS_M = (0.005, 0.02, 0.05, 0.1, 0.2)   # surface steps of the force's derivative


class Estimator:
    """Everything ekf_node computes, without ROS."""

    def __init__(self, vehicle: Vehicle, settings: EkfSettings, soil: SoilParams) -> None:
        self.vehicle = vehicle
        self.settings = settings
        self.soil = soil
        body = vehicle.body
        # the hull cylinders: waterline length centred on base_link (under the LCG), as the
        # simulator's hull strips; inside bow_x_m .. stern_x_m of the overall length
        self.hull_bow_x_m = min(0.5 * body.hull_length_m, body.bow_x_m)
        self.hull_stern_x_m = max(-0.5 * body.hull_length_m, body.stern_x_m)
        self.section = buoyancy.HullSection.of_body(body)
        # the most the hulls can displace, deck awash
        self.max_volume_m3 = 2.0 * self.section.max_area_m2() * body.hull_length_m
        # lying this deep (halfway from the displacement to the deck awash) it floats, whatever
        # the IMU says
        self.sure_float_m3 = 0.5 * (body.displaced_volume_m3 + self.max_volume_m3)
        self.track_area_m2 = body.track_width_m * body.track_contact_length_m
        # the heave mass and damping of the hulls' section about the float line (the simulator's)
        heave = heave_constants(body, settings.heave_natural_hz, settings.heave_damping_ratio)
        self.heave_mass_kg = heave.mass_kg
        self.heave_damping_n_per_mps = heave.damping_n_per_mps
        self.counters: dict[str, dict[Outcome, int]] = {s: defaultdict(int) for s in SENSORS}
        self.rates = {s: RateCounter() for s in SENSORS}
        self.reset()

    # ------------------------------------------------------------------ state
    def reset(self) -> None:
        """Forget everything but the counters: back to the initial covariance."""
        st = self.settings
        p0 = np.array([st.init_position_m ** 2, st.init_position_m ** 2, st.init_yaw_rad ** 2,
                       st.init_velocity_mps ** 2, st.init_velocity_mps ** 2,
                       st.init_yaw_rate_rps ** 2, st.init_gyro_bias_rps ** 2,
                       st.waterline_sigma_m ** 2, st.wave_sigma_m ** 2 + 1e-6,
                       (st.wave_sigma_m * 2 * math.pi * st.wave_peak_frequency_hz) ** 2 + 1e-6,
                       st.gps_bias_sigma_m ** 2, st.gps_bias_sigma_m ** 2])
        noise = ProcessNoise(st.q_position_m, st.q_yaw_rad, st.q_accel_mps2, st.q_yaw_accel_rps2,
                             st.q_gyro_bias_rps, st.q_waterline_m,
                             2 * math.pi * st.wave_peak_frequency_hz, st.wave_damping_ratio,
                             st.wave_sigma_m, st.gps_bias_sigma_m, st.gps_bias_tau_s)
        self.ekf = MotionEkf(np.zeros(N_STATES), p0, noise, st.seaward_yaw_rad)
        self.t_s: float | None = None
        self.last_t = {s: -math.inf for s in SENSORS}
        self.datum: tuple[float, float, float] | None = None
        if not st.datum_from_first_fix:
            self.datum = (st.datum_latitude_deg, st.datum_longitude_deg, st.datum_altitude_m)
        self.position_set = False
        self.yaw_set = False
        self.imu: ImuSample | None = None
        self.accel_base = (math.nan, math.nan, math.nan)   # specific force at base_link
        self.tracks: DriveStatus | None = None
        self.props: DriveStatus | None = None
        self.slope_rad = self.vehicle.site.beach_slope_rad
        self.fraction = 1.0
        self.afloat = False
        self.motion = 0.0                # > 1: rolling, pitching, heaving like a floating hull
        self._heave_mean_mps2 = 0.0      # slow mean of the heave acceleration (tilt, bias)
        self.heave_velocity_mps = 0.0
        self._fraction_t_s = -math.inf
        self._force_update_t = -math.inf
        self._grounded_since_s = math.inf
        self.force = [ForceSmoother(st.force_process_n_per_s, st.force_measurement_n)
                      for _ in range(2)]

    def set_pose(self, x_m: float, y_m: float, yaw_rad: float) -> bool:
        """Reset the pose in odom; the waterline distance follows the new position."""
        if not all(math.isfinite(v) for v in (x_m, y_m, yaw_rad)):
            return False
        self.ekf.set_pose(x_m, y_m, yaw_rad, self.settings.init_position_m,
                          self.settings.init_yaw_rad)
        self._init_waterline()
        self.position_set = self.yaw_set = True
        return True

    def pin_surface(self, waterline_distance_m: float, wave_elevation_m: float) -> bool:
        """Set the waterline distance and the wave at base_link, m (a diagnostic: what the
        submersion would be with the surface known, ``evaluate --oracle-surface``)."""
        if not (math.isfinite(waterline_distance_m) and math.isfinite(wave_elevation_m)):
            return False
        self.ekf.x[Idx.S] = waterline_distance_m
        self.ekf.x[Idx.ETA] = wave_elevation_m
        return True

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
    def _fresh(self, sensor: str, t_s: float) -> bool:
        return t_s - self.last_t[sensor] <= self.settings.sensor_timeout_s

    def advance(self, t_s: float) -> None:
        """Predict the filter forward to ``t_s`` (no-op when ``t_s`` is not newer)."""
        if self.t_s is None:
            self.t_s = t_s
            return
        while t_s > self.t_s:
            dt = min(MAX_PREDICT_STEP_S, t_s - self.t_s)
            self._predict(dt)
            self.t_s += dt

    def _predict(self, dt: float) -> None:
        x = self.ekf.x
        st = self.settings
        now = self.t_s + dt
        imu = self.imu
        accel = None
        noise = None
        target = None
        if imu is not None and self._fresh('imu', now) and math.isfinite(self.accel_base[0]):
            # gravity along the body axes from the attitude, scaled by the measured vertical
            # specific force (heave accelerations afloat): g_up = f_z / (cos roll cos pitch)
            fx, fy, fz = self.accel_base
            tilt = math.cos(imu.roll_rad) * math.cos(imu.pitch_rad)
            g_up = fz / max(tilt, 0.5)
            accel = (fx + g_up * math.sin(imu.pitch_rad) + x[Idx.R] * x[Idx.V],
                     fy - g_up * math.sin(imu.roll_rad) * math.cos(imu.pitch_rad)
                     - x[Idx.R] * x[Idx.U])
        else:
            noise = st.q_accel_no_imu_mps2
            target = self._drive_target(now)
        self.ekf.predict(dt, accel, target, noise, self.vehicle.site.beach_slope_rad)

    def _drive_target(self, now: float) -> tuple[float, float, float] | None:
        st = self.settings
        tau = st.drive_time_constant_s
        if self.fraction > GROUNDED_FRACTION and self.tracks is not None \
                and self._fresh('tracks', now):
            vp, vs = self.tracks.port.speed_mps, self.tracks.stbd.speed_mps
            return 0.5 * (vp + vs), (vs - vp) / st.effective_track_width_m, tau
        if self.props is not None and self._fresh('props', now):
            thrust = self.props.port.force_n + self.props.stbd.force_n
            speed = math.copysign(math.sqrt(abs(thrust) / st.water_drag_n_per_mps2), thrust)
            return speed, float(self.ekf.x[Idx.R]), tau
        return None

    def _admit(self, sensor: str, t_s: float, values: tuple[float, ...]) -> Outcome | None:
        """Common checks; returns a rejection outcome, or None when the sample may be used."""
        if not self.settings.sensor_enabled(sensor):
            return self._count(sensor, Outcome.IGNORED)
        if not all(math.isfinite(v) for v in (t_s, *values)):
            return self._count(sensor, Outcome.REJECTED_NAN)
        too_old = self.t_s is not None and t_s < self.t_s - self.settings.max_lag_s
        if t_s <= self.last_t[sensor] or too_old:
            return self._count(sensor, Outcome.REJECTED_OUT_OF_ORDER)
        self.advance(t_s)
        self.last_t[sensor] = t_s
        self.rates[sensor].tick(t_s)
        return None

    def _count(self, sensor: str, outcome: Outcome) -> Outcome:
        self.counters[sensor][outcome] += 1
        return outcome

    # ------------------------------------------------------------------ sensors
    def add_imu(self, s: ImuSample) -> Outcome:
        """Attitude, gyro rate and accelerations; corrects yaw rate, bias and heading."""
        rejected = self._admit('imu', s.t_s, (s.roll_rad, s.pitch_rad, s.yaw_rate_rps,
                                              s.roll_rate_rps, s.pitch_rate_rps))
        if rejected:
            return rejected
        dt = s.t_s - self.imu.t_s if self.imu is not None else 0.0
        self.accel_base = self._accel_at_base_link(s, dt)
        self.imu = s
        self._update_motion(s, dt)
        self._update_heave_velocity(dt)
        st = self.settings
        h = np.zeros(N_STATES)
        h[Idx.R] = h[Idx.BIAS] = 1.0
        var = s.yaw_rate_var_rps2 if s.yaw_rate_var_rps2 > 0 else st.gyro_rps ** 2
        out = self.ekf.update_scalar(s.yaw_rate_rps, self.ekf.x[Idx.R] + self.ekf.x[Idx.BIAS],
                                     h, var, st.gate_imu)
        if math.isfinite(s.yaw_rad):
            if not self.yaw_set:
                self.ekf.x[Idx.YAW] = wrap_angle(s.yaw_rad)
                self.yaw_set = True
            h = np.zeros(N_STATES)
            h[Idx.YAW] = 1.0
            var = s.yaw_var_rad2 if s.yaw_var_rad2 > 0 else st.yaw_rad ** 2
            yaw_out = self.ekf.update_scalar(s.yaw_rad, self.ekf.x[Idx.YAW], h, var,
                                             st.gate_imu, angle=True)
            if yaw_out is not Outcome.ACCEPTED:
                out = yaw_out
        self._update_slope(s, dt)
        return self._count('imu', out)

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

    def _update_motion(self, s: ImuSample, dt: float) -> None:
        """Low-pass of (roll/pitch rate, heave acceleration) over their thresholds, squared."""
        st = self.settings
        heave = self._heave_accel_mps2()
        heave = heave if math.isfinite(heave) else 0.0
        level = ((s.roll_rate_rps ** 2 + s.pitch_rate_rps ** 2) / st.contact_rate_rps ** 2
                 + heave ** 2 / st.contact_accel_mps2 ** 2)
        alpha = min(dt / st.contact_time_constant_s, 1.0) if dt > 0.0 else 1.0
        self.motion += alpha * (level - self.motion)

    def _heave_accel_mps2(self) -> float:
        """Vertical acceleration of base_link: the IMU's specific force over the tilt, less
        g (NaN without an IMU sample)."""
        imu = self.imu
        fz = self.accel_base[2]
        if imu is None or not math.isfinite(fz):
            return math.nan
        tilt = math.cos(imu.roll_rad) * math.cos(imu.pitch_rad)
        return fz / max(tilt, 0.5) - self.vehicle.body.gravity_mps2

    def _update_heave_velocity(self, dt: float) -> None:
        """Heave velocity from the heave acceleration: its slow mean (attitude error, bias)
        removed, then a leaky integral (heave.velocity_time_constant_s)."""
        accel = self._heave_accel_mps2()
        if not math.isfinite(accel) or not 0.0 < dt <= 5 * MAX_PREDICT_STEP_S:
            return
        tau = self.settings.heave_velocity_tau_s
        self._heave_mean_mps2 += min(dt / (4.0 * tau), 1.0) * (accel - self._heave_mean_mps2)
        self.heave_velocity_mps += dt * (accel - self._heave_mean_mps2) \
            - min(dt / tau, 1.0) * self.heave_velocity_mps

    def _update_slope(self, s: ImuSample, dt: float) -> None:
        """Low-pass the beach slope along the seaward direction from pitch and roll."""
        if s.t_s - self._fraction_t_s >= FRACTION_PERIOD_S:
            self.traction()          # refreshes the weight share
        if self.fraction <= SLOPE_FRACTION:
            return
        rel = self.ekf.x[Idx.YAW] - self.settings.seaward_yaw_rad
        measured = s.pitch_rad * math.cos(rel) + s.roll_rad * math.sin(rel)
        alpha = min(dt / self.settings.slope_time_constant_s, 1.0)
        self.slope_rad += alpha * (measured - self.slope_rad)

    def _mast_attitude(self) -> tuple[float, float, float, float]:
        """(roll, pitch, roll rate, pitch rate) of the last IMU sample for the antenna's lever
        arm (level and still without one)."""
        imu = self.imu
        if imu is None:
            return 0.0, 0.0, 0.0, 0.0
        return imu.roll_rad, imu.pitch_rad, imu.roll_rate_rps, imu.pitch_rate_rps

    def add_gps_fix(self, s: GpsFix) -> Outcome:
        """DGPS position (geodetic) -> local ENU at the datum; corrects x, y."""
        if not s.valid and self.settings.use_gps_fix:
            return self._count('gps_fix', Outcome.IGNORED)
        rejected = self._admit('gps_fix', s.t_s, (s.latitude_deg, s.longitude_deg, s.altitude_m))
        if rejected:
            return rejected
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
        out = self.ekf.update(np.array([east, north]), predicted, H, np.eye(2) * var,
                              self.settings.gate_gps_fix)
        return self._count('gps_fix', out)

    def add_gps_velocity(self, s: GpsVelocity) -> Outcome:
        """DGPS ground velocity of the antenna (ENU); corrects u, v and yaw."""
        rejected = self._admit('gps_vel', s.t_s, (s.east_mps, s.north_mps))
        if rejected:
            return rejected
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
        return self._count('gps_vel', out)

    def add_water_contact(self, s: WaterContact) -> Outcome:
        """Wet/dry sensors: where the state disagrees, the surface is at the sensor."""
        rejected = self._admit('water', s.t_s, ())
        if rejected:
            return rejected
        if self.afloat:
            # floating, the sensors ride with the hull, not at a height above the sand
            return self._count('water', Outcome.ACCEPTED)
        mounts = self.vehicle.sensors
        out = Outcome.IGNORED
        for wet, x_m, z_m in ((s.fore_wet, mounts.fore_water_x_m, mounts.fore_water_z_m),
                              (s.aft_wet, mounts.aft_water_x_m, mounts.aft_water_z_m)):
            depth, h = self._sensor_depth(x_m, z_m)
            if bool(wet) == (depth > 0.0):
                continue
            result = self.ekf.update_scalar(0.0, depth, h, self.settings.contact_m ** 2,
                                            self.settings.gate_water, only=SURFACE_STATES)
            if out is not Outcome.REJECTED_OUTLIER:
                out = result
        if out is Outcome.IGNORED:
            out = Outcome.ACCEPTED    # consistent with the state: nothing to correct
        return self._count('water', out)

    def _sensor_depth(self, x_m: float, z_m: float) -> tuple[float, np.ndarray]:
        """Water over a sensor at body (x, z) of a vehicle on the slope, and its Jacobian."""
        x = self.ekf.x
        sin_t, cos_t = math.sin(self.slope_rad), math.cos(self.slope_rad)
        rel = x[Idx.YAW] - self.settings.seaward_yaw_rad
        depth = x[Idx.ETA] + (x[Idx.S] + x_m * math.cos(rel)) * sin_t - z_m * cos_t
        h = np.zeros(N_STATES)
        h[Idx.ETA] = 1.0
        h[Idx.S] = sin_t
        h[Idx.YAW] = -x_m * math.sin(rel) * sin_t
        return depth, h

    def add_depth(self, s: DepthReading) -> Outcome:
        """A valid sounding means the transducer floats above the sea bed: corrects s, eta."""
        if not s.valid:
            rejected = self._admit('depth', s.t_s, ())
            return rejected or self._count('depth', Outcome.IGNORED)
        rejected = self._admit('depth', s.t_s, (s.depth_m,))
        if rejected:
            return rejected
        x = self.ekf.x
        body, mounts, site = self.vehicle.body, self.vehicle.sensors, self.vehicle.site
        sin_t = math.sin(self.slope_rad)
        floor_depth = x[Idx.S] * sin_t
        h = np.zeros(N_STATES)
        h[Idx.ETA] = 1.0
        if floor_depth < site.sea_floor_depth_m:
            h[Idx.S] = sin_t
        floor_depth = min(floor_depth, site.sea_floor_depth_m)
        predicted = x[Idx.ETA] - body.draft_m + mounts.depth_sounder_z_m + floor_depth
        out = self.ekf.update_scalar(s.depth_m, predicted, h, self.settings.depth_m ** 2,
                                     self.settings.gate_depth, only=WATERLINE_STATE)
        return self._count('depth', out)

    def add_tracks(self, s: DriveStatus) -> Outcome:
        """Track speeds (slip, drive model) and measured forces (smoothed)."""
        values = (s.port.speed_mps, s.stbd.speed_mps)
        rejected = self._admit('tracks', s.t_s, values)
        if rejected:
            return rejected
        self.tracks = s
        gain = self.vehicle.drivetrain.track_force_gain_n_per_a
        for smoother, side in zip(self.force, (s.port, s.stbd), strict=True):
            force = side.force_n if math.isfinite(side.force_n) else side.current_a * gain
            smoother.update(s.t_s, force)
        if not self._fresh('gps_vel', s.t_s) and self.fraction > GROUNDED_FRACTION:
            self._track_odometry(s)
        self._track_force_update(s)
        return self._count('tracks', Outcome.ACCEPTED)

    def _track_force_update(self, s: DriveStatus) -> None:
        """The smoothed track forces against the Wong force of the estimated weight: a
        measurement of the surface (vehicle.md 6), where both tracks turn and slip enough for
        the force to depend on the weight (a stopped or gripping track takes whatever force
        holds it), ``force_update.settle_s`` after a touchdown, and the surface can change
        the force (``_force_per_m``). The ground speed's uncertainty joins the force noise
        through the slip."""
        st = self.settings
        if self.afloat:
            self._grounded_since_s = math.inf
            return
        self._grounded_since_s = min(self._grounded_since_s, s.t_s)
        if st.force_update_sigma_n <= 0.0 \
                or s.t_s - self._grounded_since_s < st.force_update_settle_s \
                or s.t_s - self._force_update_t < st.force_update_period_s:
            return
        speeds = (s.port.speed_mps, s.stbd.speed_mps)
        ground = self._ground_speeds()
        slips = [float(traction.slip(speeds[k], ground[k])) for k in range(2)]
        if not all(abs(speeds[k]) >= st.force_update_min_track_speed_mps
                   and abs(slips[k]) >= st.force_update_min_slip for k in range(2)):
            return
        measured = [self._measured_soil_force_n(k) for k in range(2)]
        if not all(math.isfinite(m) for m in measured):
            return
        self._force_update_t = s.t_s
        x, P = self.ekf.x, self.ekf.P
        sin_t = math.sin(self.slope_rad)
        half = 0.5 * self.vehicle.body.hull_separation_m
        step_mps = 0.01
        for k in range(2):
            lever = -half if k == 0 else half
            predicted = self._soil_force_n(x[Idx.S], x[Idx.ETA], speeds[k], ground[k])
            per_m = self._force_per_m(predicted, measured[k], speeds[k], ground[k])
            if per_m is None:
                continue                 # the surface cannot explain the difference
            per_mps = (self._soil_force_n(x[Idx.S], x[Idx.ETA], speeds[k], ground[k] + step_mps)
                       - predicted) / step_mps
            ground_var = P[Idx.U, Idx.U] + lever * lever * P[Idx.R, Idx.R] \
                + 2.0 * lever * P[Idx.U, Idx.R]
            h = np.zeros(N_STATES)
            h[Idx.ETA] = per_m
            h[Idx.S] = per_m * sin_t     # the volume follows the water depth eta + s sin
            var = st.force_update_sigma_n ** 2 + per_mps * per_mps * max(ground_var, 0.0)
            self.ekf.update_scalar(measured[k], predicted, h, var, st.force_update_gate,
                                   only=SURFACE_STATES)

    def _force_per_m(self, predicted_n: float, measured_n: float, track_mps: float,
                     ground_mps: float) -> float | None:
        """d force / d surface, N/m; None where the surface cannot change the force.

        Where the estimate puts no weight on the tracks (the volume capped at the
        displacement) the local derivative is nil, and a track clearly pushing under a hull
        thought afloat would be ignored: when the force asks for less water, the secant over
        the first of growing steps down that changes the force is used instead. On dry
        sand (all the weight on the tracks) a force short of the model's says more about the
        soil than about water, and only the local derivative counts.
        """
        x = self.ekf.x
        less_water = measured_n > predicted_n
        steps, direction = (SECANT_STEPS_M, -1.0) if less_water else (SECANT_STEPS_M[:1], 1.0)
        for step_m in steps:
            moved = self._soil_force_n(x[Idx.S], x[Idx.ETA] + direction * step_m, track_mps,
                                       ground_mps)
            if abs(moved - predicted_n) > 1e-3:
                return (moved - predicted_n) / (direction * step_m)
        return None

    def _ground_speeds(self) -> tuple[float, float]:
        """Ground speed under the port and starboard tracks, m/s."""
        x = self.ekf.x
        half = 0.5 * self.vehicle.body.hull_separation_m
        return x[Idx.U] - x[Idx.R] * half, x[Idx.U] + x[Idx.R] * half

    def _soil_force_n(self, waterline_distance_m: float, surface_m: float,
                      track_mps: float, ground_mps: float) -> float:
        """Soil force on the vehicle from one track at these speeds, with the weight the
        surface leaves it, N."""
        body = self.vehicle.body
        heading_cos = math.cos(self.ekf.x[Idx.YAW] - self.settings.seaward_yaw_rad)
        volume = buoyancy.grounded_volume_m3(waterline_distance_m, self.slope_rad,
                                             body.hull_clearance_m, self.hull_bow_x_m,
                                             self.hull_stern_x_m, body.hull_radius_m,
                                             surface_m, heading_cos, self.section)
        weight = traction.effective_weight_n(body.displacement_n,
                                             min(volume, body.displaced_volume_m3),
                                             self.slope_rad, body.water_density_kgpm3,
                                             body.gravity_mps2)
        return float(traction.track_force_n(track_mps, ground_mps, 0.5 * weight, self.soil,
                                            self.track_area_m2, body.track_contact_length_m))

    def _track_odometry(self, s: DriveStatus) -> None:
        """GPS velocity stale on land: the tracks say roughly how fast we go."""
        st = self.settings
        H = np.zeros((2, N_STATES))
        H[0, Idx.U] = H[1, Idx.R] = 1.0
        z = np.array([0.5 * (s.port.speed_mps + s.stbd.speed_mps),
                      (s.stbd.speed_mps - s.port.speed_mps) / st.effective_track_width_m])
        var = st.track_odometry_mps ** 2
        R = np.diag([var, var / st.effective_track_width_m ** 2])
        self.ekf.update(z, self.ekf.x[[Idx.U, Idx.R]], H, R, math.inf)

    def add_props(self, s: DriveStatus) -> Outcome:
        """Propeller thrusts, for the drive model afloat."""
        rejected = self._admit('props', s.t_s, (s.port.force_n, s.stbd.force_n))
        if rejected:
            return rejected
        self.props = s
        return self._count('props', Outcome.ACCEPTED)

    # ------------------------------------------------------------------ outputs
    def odometry(self) -> OdometryEstimate:
        """Pose and twist of base_link in odom with covariances."""
        x, P = self.ekf.x, self.ekf.P
        roll = self.imu.roll_rad if self.imu else 0.0
        pitch = self.imu.pitch_rad if self.imu else 0.0
        pose_cov = np.diag([0.0, 0.0, 1e3, 1e-2, 1e-2, 0.0])
        ix = [Idx.X, Idx.Y]
        pose_cov[np.ix_([0, 1], [0, 1])] = P[np.ix_(ix, ix)]
        pose_cov[np.ix_([0, 1], [5])] = P[np.ix_(ix, [Idx.YAW])]
        pose_cov[np.ix_([5], [0, 1])] = P[np.ix_([Idx.YAW], ix)]
        pose_cov[5, 5] = P[Idx.YAW, Idx.YAW]
        twist_cov = np.diag([0.0, 0.0, 1e3, 1e3, 1e3, 0.0])
        it = [Idx.U, Idx.V]
        twist_cov[np.ix_([0, 1], [0, 1])] = P[np.ix_(it, it)]
        twist_cov[5, 5] = P[Idx.R, Idx.R]
        z = -x[Idx.S] * math.sin(self.slope_rad)
        return OdometryEstimate(self.t_s or 0.0, float(x[Idx.X]), float(x[Idx.Y]), z, roll,
                                pitch, float(x[Idx.YAW]), float(x[Idx.U]), float(x[Idx.V]),
                                float(x[Idx.R]), pose_cov, twist_cov)

    def traction(self) -> TractionEstimate:
        """Slip per track, submersion (h2, volume, W_e, weight share) and track forces."""
        x = self.ekf.x
        body = self.vehicle.body
        slope = self.slope_rad
        heading_cos = math.cos(x[Idx.YAW] - self.settings.seaward_yaw_rad)
        args = (x[Idx.S], slope, body.hull_clearance_m, self.hull_bow_x_m, self.hull_stern_x_m)
        h2 = buoyancy.submerged_length_m(*args, x[Idx.ETA], heading_cos)
        volume = buoyancy.grounded_volume_m3(*args, body.hull_radius_m, x[Idx.ETA], heading_cos,
                                             self.section)
        afloat = self.afloat = self._floating(volume)
        if afloat:
            volume = self._afloat_volume()
        else:
            volume = min(volume, body.displaced_volume_m3)   # on the sand: it does not float
        weight = 0.0 if afloat else traction.effective_weight_n(
            body.displacement_n, volume, slope, body.water_density_kgpm3, body.gravity_mps2)
        self.fraction = weight / (body.displacement_n * math.cos(slope))
        self._fraction_t_s = self.t_s or 0.0
        ground = self._ground_speeds()
        slips = [math.nan, math.nan]
        predicted = [math.nan, math.nan]
        if self.tracks is not None:
            speeds = (self.tracks.port.speed_mps, self.tracks.stbd.speed_mps)
            for k in range(2):
                slips[k] = traction.slip(speeds[k], ground[k])
                predicted[k] = traction.track_force_n(speeds[k], ground[k], 0.5 * weight,
                                                      self.soil, self.track_area_m2,
                                                      body.track_contact_length_m)
        return TractionEstimate(self.t_s or 0.0, slips[0], slips[1], volume, weight,
                                self.fraction, float(x[Idx.S]), h2, slope, predicted[0],
                                predicted[1], self._measured_soil_force_n(0),
                                self._measured_soil_force_n(1),
                                afloat, float(x[Idx.ETA]))

    def _floating(self, grounded_volume_m3: float) -> bool:
        """Afloat or on the sand: the IMU's motion test when fresh, else the geometry.

        Deep enough water (the estimated surface gives the displacement; with hysteresis: once
        afloat, the hulls must sit clearly shallower to touch down) floats it. In the surf, the
        IMU tells: on the sand the vehicle lies on the beach (no roll/pitch rate, no heave
        acceleration); floating, it rolls, pitches and heaves with the waves.
        """
        displaced = self.vehicle.body.displaced_volume_m3
        if self._tracks_pushing():
            return False
        limit = displaced * (TOUCHDOWN_SHARE if self.afloat else 1.0)
        imu_fresh = self.imu is not None and self.t_s is not None and self._fresh('imu', self.t_s)
        if grounded_volume_m3 >= limit:
            # deep enough to float even in calm water - unless the IMU says the vehicle lies
            # still on the sand, in a trough the estimated surface does not show
            return not imu_fresh or self.motion > 1.0 \
                or grounded_volume_m3 >= self.sure_float_m3
        if imu_fresh:
            return self.motion > 1.0 and \
                grounded_volume_m3 >= self.settings.contact_min_volume_share * displaced
        return False

    def _tracks_pushing(self) -> bool:
        """Both tracks push or brake the vehicle harder than water could (paddling belts,
        a held belt's drag): on the sand. From the smoothed forces less the drivetrain
        friction, fresh status only; a held (stopped) belt braking counts as well."""
        st = self.settings
        if st.contact_track_force_n <= 0.0 or self.tracks is None or self.t_s is None \
                or not self._fresh('tracks', self.t_s):
            return False
        return all(abs(self._measured_soil_force_n(k)) >= st.contact_track_force_n
                   for k in range(2))

    def _measured_soil_force_n(self, k: int) -> float:
        """Track k's (0 port, 1 starboard) smoothed current x gain less the drivetrain's own
        friction (no-load current, belt), which opposes the belt, not the sand: the soil's
        force, N (NaN before a status). The friction fades in over the first
        ``drivetrain.friction_fade_mps`` of belt speed, as in the simulator."""
        force = self.force[k].force_n
        if self.tracks is None or not math.isfinite(force):
            return math.nan
        speed = (self.tracks.port, self.tracks.stbd)[k].speed_mps
        drive = self.vehicle.drivetrain
        fade = math.tanh(speed / drive.friction_fade_mps)
        return force - drive.track_friction_n(k == 0) * fade

    def _afloat_volume(self) -> float:
        """Floating: the displacement, plus what the heave acceleration says (IMU fresh)."""
        body = self.vehicle.body
        heave_accel = self._heave_accel_mps2()
        if not math.isfinite(heave_accel) or self.t_s is None \
                or not self._fresh('imu', self.t_s):
            return body.displaced_volume_m3
        volume = buoyancy.afloat_dynamic_volume_m3(
            body.displacement_n + self.heave_damping_n_per_mps * self.heave_velocity_mps,
            self.heave_mass_kg, heave_accel, body.water_density_kgpm3, body.gravity_mps2)
        return min(max(volume, 0.0), self.max_volume_m3)

    def health(self, now_s: float) -> list[Health]:
        """One Health per sensor (stale -> WARN, rejections counted) and one for the filter."""
        out = []
        for sensor in SENSORS:
            counts = self.counters[sensor]
            health = Health(sensor, values={o.value: counts[o] for o in Outcome})
            health.values['rate_hz'] = round(self.rates[sensor].rate_hz(now_s), 2)
            if self.settings.sensor_enabled(sensor):
                age = now_s - self.last_t[sensor]
                if age > self.settings.sensor_timeout_s:
                    health.worsen(Level.WARN, 'silent: predict-only without it'
                                  if math.isfinite(age) else 'no data yet: predict-only')
            else:
                health.message = 'disabled'
            out.append(health)
        sigma = math.sqrt(max(self.ekf.P[Idx.X, Idx.X], self.ekf.P[Idx.Y, Idx.Y]))
        filt = Health('filter', values={'position_sigma_m': round(sigma, 3),
                                        'initialised': self.position_set and self.yaw_set})
        if not (self.position_set and self.yaw_set):
            filt.worsen(Level.WARN, 'waiting for a fix and a heading')
        out.append(filt)
        return out
