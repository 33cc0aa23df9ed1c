"""The estimator: motion EKF + slip + hull submersion + track forces, ROS-free.

Feed it ``samples`` dataclasses in time order (``add_*``), ask for ``odometry()`` and
``traction()``. It rejects NaN, out-of-order and Mahalanobis-outlier measurements and
counts them per sensor; a sensor silent for ``sensor_timeout_s`` is reported stale and the
filter goes on predicting without it (robot_localization's behaviour).

``Estimator`` composes three parts: ``motion_filter.MotionFilter`` (the EKF, its
prediction and the motion sensors), ``contact.ContactModel`` (afloat or on the sand,
the hulls' volume, the weight on the tracks) and ``surface.SurfaceObserver`` (water
contact, depth and track forces correcting the surface states) and ``heave.HeaveObserver``
(the keel on the beach, or under the wave by the hull's dynamic draft); at rest on the sand
(``stance.StanceDetector``) the ground velocity is measured as zero. The contact decision is
refreshed after every admitted sample and ``advance``; ``odometry()`` and ``traction()``
only read, so asking for the estimate twice (or never) changes nothing.
"""
from __future__ import annotations

import math
from collections import defaultdict


from dukw_common.diagnostics import Health, Level, RateCounter
from dukw_common.vehicle import SoilParams, Vehicle
from dukw_common.readings import (DepthReading, DriveStatus, GpsFix, GpsVelocity, ImuSample,
                                  WaterContact)
from dukw_model import traction
from dukw_estimation.contact import ContactModel, ground_speeds
from dukw_estimation.ekf import Idx, MotionEkf, Outcome
from dukw_estimation.heave import HeaveObserver
from dukw_estimation.motion_filter import (GROUNDED_FRACTION, TRACK_ODOMETRY_MIN_BELT_MPS,
                                           MotionFilter)
from dukw_estimation.samples import OdometryEstimate, TractionEstimate
from dukw_estimation.soil_online import OnlineSoil, OnlineSoilSettings
from dukw_estimation.stance import StanceDetector, StanceSettings
from dukw_estimation.settings import SENSORS, EkfSettings
from dukw_estimation.surface import SurfaceObserver


#: (port, starboard) before any track status
_NO_PAIR = (math.nan, math.nan)
# plain ints for the hot paths (indexing numpy with IntEnum members is slower)
_YAW, _S, _ETA, _SOIL = int(Idx.YAW), int(Idx.S), int(Idx.ETA), int(Idx.SOIL)
_HEAVE_RATE = int(Idx.HEAVE_RATE)
_ACCEL_BIAS_X, _ACCEL_BIAS_Y = int(Idx.ACCEL_BIAS_X), int(Idx.ACCEL_BIAS_Y)


class Estimator:
    """Everything ekf_node computes, without ROS."""

    def __init__(self, vehicle: Vehicle, settings: EkfSettings, soil: SoilParams) -> None:
        self.vehicle = vehicle
        self.settings = settings
        self.motion_filter = MotionFilter(vehicle, settings)
        self.contact = ContactModel(vehicle, settings, soil)
        self.online_soil = OnlineSoil(soil, online_soil_settings(settings))
        self.surface = SurfaceObserver(vehicle, settings, self.contact)
        self.heave = HeaveObserver(vehicle, settings, self.contact)
        self.stance = StanceDetector(stance_settings(settings))
        self.counters: dict[str, dict[Outcome, int]] = {s: defaultdict(int) for s in SENSORS}
        self.rates = {s: RateCounter() for s in SENSORS}
        #: sensor -> fused (the settings are frozen: looked up once)
        self._enabled = {s: settings.sensor_enabled(s) for s in SENSORS}
        self.reset()

    # ------------------------------------------------------------------ state
    @property
    def soil(self) -> SoilParams:
        """The soil the contact model uses now (the online estimate, or its prior)."""
        return self.contact.soil

    def set_soil(self, soil: SoilParams) -> None:
        """A new prior for the site's soil (e.g. a surveyed one): the online fit restarts
        from it."""
        self.online_soil.reset(soil)
        self._use_online_soil()
        self._reset_soil_scale()

    @property
    def ekf(self) -> MotionEkf:
        """The EKF (state and covariance), the motion filter's."""
        return self.motion_filter.ekf

    @property
    def t_s(self) -> float | None:
        """The filter's time, s (None before the first sample)."""
        return self.motion_filter.t_s

    def reset(self) -> None:
        """Forget everything but the counters: back to the initial covariance."""
        self.motion_filter.reset()
        self.status_ground_mps: tuple[float, float] | None = None
        # each track's slip at the last status with a fresh GPS velocity (track odometry)
        self.odometry_slips: tuple[float, float] | None = None
        self.contact.reset()
        self.surface.reset()
        self.heave.reset()
        self.stance.reset()
        self.at_rest = False            # the last IMU sample's zero-velocity decision
        self.zero_velocity_updates = 0  # accepted since the reset
        self.online_soil.reset(self.online_soil.prior)
        self._use_online_soil()

    def _use_online_soil(self) -> None:
        """The contact model takes the online soil and, when learning is on, its spread."""
        self.contact.soil = self.online_soil.soil
        if self.settings.soil_online_enabled:
            self.contact.soil_cov = self.online_soil.P.copy()

    def set_pose(self, x_m: float, y_m: float, yaw_rad: float) -> bool:
        """Reset the pose in odom; the waterline distance follows the new position."""
        if not all(math.isfinite(v) for v in (x_m, y_m, yaw_rad)):
            return False
        self.motion_filter.set_pose(x_m, y_m, yaw_rad)
        self._refresh_contact()
        return True

    def pin_surface(self, waterline_distance_m: float, wave_elevation_m: float) -> bool:
        """Set the waterline distance and the wave at base_link, m (a diagnostic: what the
        submersion would be with the surface known, ``evaluate --oracle-surface``)."""
        if not (math.isfinite(waterline_distance_m) and math.isfinite(wave_elevation_m)):
            return False
        self.ekf.x[Idx.S] = waterline_distance_m
        self.ekf.x[Idx.ETA] = wave_elevation_m
        self._refresh_contact()
        return True

    def _refresh_contact(self) -> None:
        """The contact decision for the present state (after a sample or ``advance``)."""
        motion = self.motion_filter
        imu_fresh = motion.imu is not None and motion.fresh_now('imu')
        pushing = self.contact.tracks_pushing(motion.tracks, motion.fresh_now('tracks'))
        self.contact.refresh(self.ekf.x, imu_fresh, pushing)

    def _contact_states(self) -> tuple[float, float, float]:
        """The states the contact decision reads (``ContactModel.refresh``: the submersion
        of s, eta and yaw): a heave update that moved none of them (on the sand after a
        touchdown it corrects the heave alone) leaves the decision as it was."""
        x = self.ekf.x
        return x.item(_S), x.item(_ETA), x.item(_YAW)

    # ------------------------------------------------------------------ time
    def advance(self, t_s: float) -> None:
        """Predict the filter forward to ``t_s`` (no-op when ``t_s`` is not newer) and
        refresh the contact decision for the predicted state."""
        self.motion_filter.predict_to(t_s, self.contact.fraction)
        self._refresh_contact()

    def _admit(self, sensor: str, t_s: float, values: tuple[float, ...]) -> Outcome | None:
        """Common checks; returns a rejection outcome, or None when the sample may be used
        (the filter then predicted to its time)."""
        if not self._enabled[sensor]:
            return self._count(sensor, Outcome.IGNORED)
        if not (math.isfinite(t_s) and all(map(math.isfinite, values))):
            return self._count(sensor, Outcome.REJECTED_NAN)
        motion = self.motion_filter
        now_s = motion.t_s
        too_old = now_s is not None and t_s < now_s - self.settings.max_lag_s
        if t_s <= motion.last_t[sensor] or too_old:
            return self._count(sensor, Outcome.REJECTED_OUT_OF_ORDER)
        motion.predict_to(t_s, self.contact.fraction)
        motion.last_t[sensor] = t_s
        self.rates[sensor].tick(t_s)
        return None

    def _count(self, sensor: str, outcome: Outcome) -> Outcome:
        self.counters[sensor][outcome] += 1
        return outcome

    def _settle(self, sensor: str, outcome: Outcome) -> Outcome:
        """After an admitted sample: the contact decision follows the new state."""
        self._refresh_contact()
        return self._count(sensor, outcome)

    # ------------------------------------------------------------------ sensors
    def add_imu(self, s: ImuSample) -> Outcome:
        """Attitude, gyro rate and accelerations; corrects yaw rate, bias and heading."""
        rejected = self._admit('imu', s.t_s, (s.roll_rad, s.pitch_rad, s.yaw_rate_rps,
                                              s.roll_rate_rps, s.pitch_rate_rps))
        if rejected:
            return rejected
        out, dt = self.motion_filter.add_imu(s)
        heave = self.motion_filter.heave_accel_mps2()
        self.contact.observe_imu(s, heave, dt)
        self._refresh_contact()
        before = self._contact_states()
        drop = self.contact.track_end_drop_m(s, self.ekf.x.item(_YAW))
        if self.heave.update(self.ekf, heave, self.motion_filter.position_set, drop) \
                is Outcome.ACCEPTED and self._contact_states() != before:
            self._refresh_contact()
        self._learn_slope(s, dt)
        self._zero_velocity(s)
        return self._count('imu', out)

    def _learn_slope(self, s: ImuSample, dt: float) -> None:
        """The beach slope from the IMU (``ContactModel.update_slope``). With water at the
        estimated hulls the waterline distance s is what the water's measurements (the
        sounder afloat, the wet/dry sensors, the keel at a touchdown, the track forces) made
        it, and they all see the bed's depth at base_link, s sin(slope): a new slope keeps
        that depth (s and its covariance scaled by sin(old) / sin(new)). With the hulls dry
        s is the GPS's and stays."""
        contact, ekf = self.contact, self.ekf
        before = contact.slope_rad
        contact.update_slope(s, ekf.x[Idx.YAW], dt)
        after = contact.slope_rad
        if after == before or math.sin(after) <= 0.0 or contact.surface_volume_m3(ekf.x) <= 0.0:
            return
        k = math.sin(before) / math.sin(after)
        ekf.x[_S] *= k
        ekf.P[_S, :] *= k
        ekf.P[:, _S] *= k

    def _zero_velocity(self, s: ImuSample) -> None:
        """At rest -- both belts stopped (slower than ``slip.stopped_track_mps``, their
        encoder's noise), the IMU still over ``zupt.window_s`` (stance.py: its motion within
        the noise, its mean acceleration and tilt rates small) and the hulls on the sand --
        the ground velocity is measured as zero (``zupt.*``). Afloat the water may carry the
        hull at a speed a still IMU cannot show (calm water, belts stopped); so may the waves
        over the sand when the tracks carry little weight (the held belts' grip is the
        weight's: campaign run 104 slid at 0.09 m/s for a second at a share of 0.22, the IMU
        still), hence ``zupt.min_fraction``. The stance detector takes the surge and sway
        accelerations net of the filter's learnt accelerometer bias."""
        st, motion = self.settings, self.motion_filter
        self.at_rest = False
        if not st.zupt_enabled:
            return
        surge, sway = motion.gravity_free_accel()
        x = self.ekf.x
        still = self.stance.add(s, (surge - x[_ACCEL_BIAS_X], sway - x[_ACCEL_BIAS_Y]))
        tracks = motion.tracks
        if not still or self.contact.afloat or self.contact.fraction < st.zupt_min_fraction \
                or tracks is None \
                or not motion.fresh('tracks', s.t_s) \
                or max(abs(tracks.port.speed_mps), abs(tracks.stbd.speed_mps)) \
                >= st.slip_stopped_track_mps:
            return
        self.at_rest = True
        if motion.zero_velocity(st.zupt_sigma_mps, st.zupt_gate) is Outcome.ACCEPTED:
            self.zero_velocity_updates += 1
            self._refresh_contact()

    def add_gps_fix(self, s: GpsFix) -> Outcome:
        """DGPS position (geodetic) -> local ENU at the datum; corrects x, y."""
        if not s.valid and self.settings.use_gps_fix:
            return self._count('gps_fix', Outcome.IGNORED)
        rejected = self._admit('gps_fix', s.t_s, (s.latitude_deg, s.longitude_deg, s.altitude_m))
        return rejected or self._settle('gps_fix', self.motion_filter.add_gps_fix(s))

    def add_gps_velocity(self, s: GpsVelocity) -> Outcome:
        """DGPS ground velocity of the antenna (ENU); corrects u, v and yaw."""
        rejected = self._admit('gps_vel', s.t_s, (s.east_mps, s.north_mps))
        return rejected or self._settle('gps_vel', self.motion_filter.add_gps_velocity(s))

    def add_water_contact(self, s: WaterContact) -> Outcome:
        """Wet/dry sensors: where the state disagrees, the surface is at the sensor."""
        rejected = self._admit('water', s.t_s, ())
        return rejected or self._settle('water', self.surface.water_contact(self.ekf, s))

    def add_depth(self, s: DepthReading) -> Outcome:
        """A valid sounding means the transducer floats above the sea bed: corrects s, eta."""
        if not s.valid:
            rejected = self._admit('depth', s.t_s, ())
            return rejected or self._settle('depth', Outcome.IGNORED)
        rejected = self._admit('depth', s.t_s, (s.depth_m,))
        return rejected or self._settle('depth', self.surface.depth(self.ekf, s))

    def add_tracks(self, s: DriveStatus) -> Outcome:
        """Track speeds (slip, drive model) and measured forces (smoothed)."""
        rejected = self._admit('tracks', s.t_s, (s.port.speed_mps, s.stbd.speed_mps))
        if rejected:
            return rejected
        motion = self.motion_filter
        motion.tracks = s
        # the ground under the tracks when their speeds were measured: the slip compares
        # both at one time (a belt spinning up at 0.6 m/s^2 gains 0.03 m/s between statuses)
        self.status_ground_mps = ground_speeds(self.ekf.x, self.vehicle.body.hull_separation_m)
        self.contact.smooth_track_forces(s)
        if motion.fresh('gps_vel', s.t_s):
            self.odometry_slips = self._status_slips(s)
        elif self.contact.fraction > GROUNDED_FRACTION:
            motion.track_odometry(s, self.odometry_slips)
        self._learn_soil(s)
        self.surface.track_forces(self.ekf, s)
        return self._settle('tracks', Outcome.ACCEPTED)

    def _status_slips(self, s: DriveStatus) -> tuple[float, float] | None:
        """Each track's slip at this status (its belt against the ground under it then);
        None while a belt is too slow for its slip to say the ground speed."""
        ground = self.status_ground_mps
        speeds = (s.port.speed_mps, s.stbd.speed_mps)
        if ground is None or min(abs(v) for v in speeds) < TRACK_ODOMETRY_MIN_BELT_MPS:
            return None
        return (float(traction.slip(speeds[0], ground[0])),
                float(traction.slip(speeds[1], ground[1])))

    def _learn_soil(self, s: DriveStatus) -> None:
        """On dry sand (no hull volume and no water over the tracks' patches even with the
        surface ``soil_online.dry_margin_m`` higher: saturated sand is stronger) each
        slipping track's soil force at the known weight updates the site's soil, which the
        contact model then uses."""
        online, contact, st = self.online_soil, self.contact, self.settings
        x, P, margin = self.ekf.x, self.ekf.P, st.soil_online_dry_margin_m
        if not (st.soil_online_enabled and online.due(s.t_s)) or contact.afloat \
                or contact.surface_volume_m3(x, margin) > 0.0 or contact.saturation(
                    x[Idx.S], x[Idx.ETA] + margin,
                    math.cos(x[Idx.YAW] - st.seaward_yaw_rad)) > 0.0:
            return                   # water over the hulls or the tracks' patches
        body = self.vehicle.body
        ground = ground_speeds(x, body.hull_separation_m)
        weight = 0.5 * contact.weight_n(0.0, False)
        learnt = False
        for k, side in enumerate((s.port, s.stbd)):
            slip = float(traction.slip(side.speed_mps, ground[k]))
            other = (s.stbd, s.port)[k].speed_mps
            if not online.informative(slip, side.speed_mps, other):
                continue
            lever = 0.5 * body.hull_separation_m * (-1.0 if k == 0 else 1.0)
            ground_var = max(P[Idx.U, Idx.U] + lever * lever * P[Idx.R, Idx.R]
                             + 2.0 * lever * P[Idx.U, Idx.R], 0.0)
            slip_sigma = math.sqrt(ground_var) / abs(side.speed_mps)
            force = contact.measured_soil_force_n(s, k) * math.copysign(1.0, side.speed_mps)
            learnt |= online.update(s.t_s, slip, slip_sigma, weight, force,
                                    contact.track_area_m2, body.track_contact_length_m)
        if learnt:
            self._use_online_soil()
            self._reset_soil_scale()

    def _reset_soil_scale(self) -> None:
        """The contact model's soil changed (learnt on dry sand, or a new prior): the filter's
        soil strength factor back to 1, decorrelated, its spread the prior's shrunk as the
        online fit's phi spread (tan phi carries the force at the surf's slips)."""
        st, P, i = self.settings, self.ekf.P, int(Idx.SOIL)
        shrink = self.online_soil.P[0, 0] / st.soil_online_phi_sigma_rad ** 2 \
            if st.soil_online_enabled else 1.0
        self.ekf.x[i] = 1.0
        P[i, :] = 0.0
        P[:, i] = 0.0
        P[i, i] = st.soil_scale_sigma ** 2 * min(shrink, 1.0)

    def add_props(self, s: DriveStatus) -> Outcome:
        """Propeller thrusts, for the drive model afloat."""
        rejected = self._admit('props', s.t_s, (s.port.force_n, s.stbd.force_n))
        if rejected:
            return rejected
        self.motion_filter.props = s
        return self._settle('props', Outcome.ACCEPTED)

    # ------------------------------------------------------------------ outputs
    def odometry(self) -> OdometryEstimate:
        """Pose and twist of base_link in odom with covariances."""
        return self.motion_filter.odometry(self.contact.slope_rad)

    def traction(self) -> TractionEstimate:
        """Slip per track, submersion (h2, volume, W_e, weight share) and track forces.

        A pure query: the afloat / sand decision is the one the last sample (or
        ``advance``) made; the volume and weight follow the present state."""
        x = self.motion_filter.ekf.x
        contact, motion = self.contact, self.motion_filter
        tracks = motion.tracks
        h2, grounded = contact.submersion(x)
        afloat = contact.afloat
        if afloat:
            volume = contact.afloat_volume_m3(motion.heave_accel_mps2(), x.item(_HEAVE_RATE),
                                              motion.fresh_now('imu'))
        else:
            volume = min(grounded, contact.displaced_m3)   # on the sand: it does not float
        weight = contact.weight_n(grounded, afloat)
        # the surface states as floats (the same values; numpy scalars cost more per use)
        yaw, waterline, eta, soil = (x.item(_YAW), x.item(_S), x.item(_ETA), x.item(_SOIL))
        slips, predicted = self._slips_and_forces(weight, waterline, eta, soil, yaw)
        return TractionEstimate(motion.t_s or 0.0, slips[0], slips[1], volume, weight,
                                contact.fraction_of(weight), waterline, h2,
                                contact.slope_rad, predicted[0], predicted[1],
                                contact.measured_soil_force_n(tracks, 0),
                                contact.measured_soil_force_n(tracks, 1),
                                afloat, eta)

    def _slips_and_forces(self, weight_n: float, waterline_m: float, eta_m: float,
                          soil_scale: float, yaw_rad: float
                          ) -> tuple[tuple[float, float], tuple[float, float]]:
        """Slip per track and the Wong force of ``weight_n`` at it (NaN before a status), at
        the last status's time: its belt speeds against the ground speeds then; the surface
        and the soil's strength factor are the filter's now."""
        tracks, ground = self.motion_filter.tracks, self.status_ground_mps
        if tracks is None or ground is None:
            return _NO_PAIR, _NO_PAIR
        stopped = self.settings.slip_stopped_track_mps
        port, stbd = tracks.port.speed_mps, tracks.stbd.speed_mps
        port = 0.0 if abs(port) < stopped else float(port)
        stbd = 0.0 if abs(stbd) < stopped else float(stbd)
        contact = self.contact
        saturation = contact.saturation(
            waterline_m, eta_m, math.cos(yaw_rad - self.settings.seaward_yaw_rad))
        ground_port, ground_stbd = float(ground[0]), float(ground[1])
        half_weight = 0.5 * weight_n
        return ((traction.slip_f(port, ground_port), traction.slip_f(stbd, ground_stbd)),
                (soil_scale * contact.track_force_n(port, ground_port, half_weight, saturation),
                 soil_scale * contact.track_force_n(stbd, ground_stbd, half_weight,
                                                    saturation)))

    def health(self, now_s: float) -> list[Health]:
        """One Health per sensor (stale -> WARN, rejections counted) and one for the filter."""
        out = []
        for sensor in SENSORS:
            counts = self.counters[sensor]
            health = Health(sensor, values={o.value: counts[o] for o in Outcome})
            health.values['rate_hz'] = round(self.rates[sensor].rate_hz(now_s), 2)
            if self.settings.sensor_enabled(sensor):
                age = now_s - self.motion_filter.last_t[sensor]
                if age > self.settings.sensor_timeout_s:
                    health.worsen(Level.WARN, 'silent: predict-only without it'
                                  if math.isfinite(age) else 'no data yet: predict-only')
            else:
                health.message = 'disabled'
            out.append(health)
        motion = self.motion_filter
        sigma = math.sqrt(max(self.ekf.P[Idx.X, Idx.X], self.ekf.P[Idx.Y, Idx.Y]))
        filt = Health('filter', values={'position_sigma_m': round(sigma, 3),
                                        'initialised': motion.position_set and motion.yaw_set})
        if not (motion.position_set and motion.yaw_set):
            filt.worsen(Level.WARN, 'waiting for a fix and a heading')
        out.append(filt)
        return out


def stance_settings(st: EkfSettings) -> StanceSettings:
    """The stance detector's settings from the estimator's (``zupt.*``, ``noise.gyro_rps``;
    the mean roll and pitch rate: ``contact.rate_threshold_rps``, above which the hull is
    taken to float)."""
    return StanceSettings(st.zupt_window_s, st.zupt_threshold, st.zupt_accel_sigma_mps2,
                          st.gyro_rps, st.zupt_mean_accel_mps2, st.contact_rate_rps)


def online_soil_settings(st: EkfSettings) -> OnlineSoilSettings:
    """The online soil fit's settings from the estimator's (``soil_online.*``)."""
    return OnlineSoilSettings(
        st.soil_online_enabled, st.soil_online_phi_min_rad, st.soil_online_phi_max_rad,
        st.soil_online_k_min_m, st.soil_online_k_max_m, st.soil_online_phi_sigma_rad,
        st.soil_online_k_sigma_m, st.soil_online_force_sigma_n, st.soil_online_min_slip,
        st.soil_online_min_track_speed_mps, st.soil_online_max_turn_mps,
        st.soil_online_max_slip_sigma, st.soil_online_period_s)
