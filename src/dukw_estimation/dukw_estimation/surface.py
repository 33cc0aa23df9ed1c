"""Where the water surface is: corrections of the filter's surface states, ROS-free.

The waterline distance s and the wave elevation eta (``ekf.SURFACE_STATES``) are measured
by the wet/dry sensors, the depth sounder and, on the sand, the track forces (through the
weight the surface leaves on the tracks, ``contact.ContactModel``). Each update here
touches only the surface states of the shared ``MotionEkf``.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from dukw_common.vehicle import Vehicle
from dukw_model import traction
from dukw_estimation.contact import ContactModel, ground_speeds
from dukw_estimation.ekf import (N_STATES, SURFACE_STATES, WATER_SURFACE_STATES, WATERLINE_STATE,
                                 Idx, MotionEkf, Outcome)
from dukw_common.readings import DepthReading, DriveStatus, WaterContact
from dukw_estimation.settings import EkfSettings

SECANT_STEPS_M = (0.005, 0.02, 0.05, 0.1, 0.2)   # surface steps of the force's derivative
SOIL_STEPS = (1e-3, 1e-3)                         # phi (rad), k (m) steps of the same


class SurfaceObserver:
    """The surface measurements: water contact, depth soundings, track forces."""

    def __init__(self, vehicle: Vehicle, settings: EkfSettings, contact: ContactModel) -> None:
        self.vehicle = vehicle
        self.settings = settings
        self.contact = contact
        self.reset()

    def reset(self) -> None:
        """Forget when the tracks touched down and when their forces were last used."""
        self.grounded_since_s = math.inf
        self.force_update_t_s = -math.inf
        self.dry_sensors: tuple[tuple[float, float], ...] = ()   # (x, z): both read dry
        self.dry_t_s = -math.inf                                 # ... at this time
        self.bracket_t_s = -math.inf     # the last update from one sensor wet, one dry

    # ------------------------------------------------------------------ wet / dry
    def water_contact(self, ekf: MotionEkf, s: WaterContact) -> Outcome:
        """Wet/dry sensors: where the state disagrees, the surface is at the sensor."""
        self.dry_sensors = ()
        if self.contact.afloat:
            # floating, the sensors ride with the hull, not at a height above the sand
            return Outcome.ACCEPTED
        mounts = self.vehicle.sensors
        sensors = ((s.fore_wet, mounts.fore_water_x_m, mounts.fore_water_z_m),
                   (s.aft_wet, mounts.aft_water_x_m, mounts.aft_water_z_m))
        out = Outcome.IGNORED
        for wet, x_m, z_m in sensors:
            depth, h = self._sensor_depth(ekf.x, x_m, z_m)
            if bool(wet) == (depth > 0.0):
                continue
            result = ekf.update_scalar(0.0, depth, h, self.contact_variance_m2(x_m),
                                       self.settings.gate_water, only=SURFACE_STATES)
            self.clip_soil_scale(ekf)
            if out is not Outcome.REJECTED_OUTLIER:
                out = result
        if bool(s.fore_wet) != bool(s.aft_wet):
            self._bracket(ekf, s.t_s, sensors)
        if out is Outcome.IGNORED:
            out = Outcome.ACCEPTED    # consistent with the state: nothing to correct
        if self.settings.water_dry_bound:
            both_dry = not (s.fore_wet or s.aft_wet)
            self.dry_sensors = tuple((x_m, z_m) for _, x_m, z_m in sensors) if both_dry else ()
            self.dry_t_s = s.t_s
            self.bound_by_dry_sensors(ekf, s.t_s)
        return out

    def contact_variance_m2(self, x_m: float) -> float:
        """The variance of the surface at a wet/dry sensor ``x_m`` ahead of base_link as a
        measurement of the surface states, m^2: the boundary's own (``noise.contact_m``) and
        the sea's slope over the hulls (``noise.contact_surface_slope``), which the one level
        surface of the states does not have: a wave over the 2.4 m between the sensors lifts
        one end against the other (issue 18: in the swash the landward sensor stayed wet
        while the water at base_link fell, and pinned the surface 5-10 cm high)."""
        st = self.settings
        return st.contact_m ** 2 + (st.contact_surface_slope * x_m) ** 2

    def _bracket(self, ekf: MotionEkf, t_s: float, sensors: tuple) -> None:
        """One sensor wet, the other dry: the surface crosses the hulls somewhere between
        the two sensors' heights, as likely anywhere in that span (width w): the mean of
        the two sensors' water depths is 0 with variance w^2 / 12. Without it only the
        span's ends (the gated updates above) speak, and on a soil other than the model's
        the track forces hold the surface at the end with more water (issue 18). At most
        every ``contact.bracket_period_s``: the surface's place within the span is the
        same error from sample to sample until the waves move it."""
        st = self.settings
        if st.contact_bracket_period_s <= 0.0 or t_s - self.bracket_t_s \
                < st.contact_bracket_period_s:
            return
        (d0, h0), (d1, h1) = (self._sensor_depth(ekf.x, x_m, z_m) for _, x_m, z_m in sensors)
        width = abs(d0 - d1)
        if width <= 0.0:
            return
        self.bracket_t_s = t_s
        ekf.update_scalar(0.0, 0.5 * (d0 + d1), 0.5 * (h0 + h1), width * width / 12.0,
                          st.gate_water, only=SURFACE_STATES)
        self.clip_soil_scale(ekf)

    def bound_by_dry_sensors(self, ekf: MotionEkf, t_s: float) -> None:
        """Both sensors last read dry (fresh, on the sand): the surface is below both (the
        hulls out of the water; one sensor dry under a wave's crest between them says less,
        and its debounced flag lags a rising surface: left to the gated update). Where
        the state has water over one, project the surface states onto its bound (the
        covariance-weighted least change, Simon 2010, Kalman filtering with state
        constraints; the covariance is left as it is)."""
        if self.contact.afloat or t_s - self.dry_t_s > self.settings.sensor_timeout_s:
            return
        for x_m, z_m in self.dry_sensors:
            depth, h = self._sensor_depth(ekf.x, x_m, z_m)
            if depth <= 0.0:
                continue
            h_surface = h * SURFACE_STATES
            p_h = ekf.P @ h_surface
            spread = float(h_surface @ p_h)
            if spread > 0.0:
                ekf.x -= SURFACE_STATES * p_h * (depth / spread)
                self.clip_soil_scale(ekf)

    def _sensor_depth(self, x: np.ndarray, x_m: float, z_m: float) -> tuple[float, np.ndarray]:
        """Water over a sensor at body (x, z) of a vehicle on the slope, and its Jacobian."""
        slope = self.contact.slope_rad
        sin_t, cos_t = math.sin(slope), math.cos(slope)
        rel = x[Idx.YAW] - self.settings.seaward_yaw_rad
        depth = x[Idx.ETA] + (x[Idx.S] + x_m * math.cos(rel)) * sin_t - z_m * cos_t
        h = np.zeros(N_STATES)
        h[Idx.ETA] = 1.0
        h[Idx.S] = sin_t
        h[Idx.YAW] = -x_m * math.sin(rel) * sin_t
        return depth, h

    # ------------------------------------------------------------------ sounder
    def depth(self, ekf: MotionEkf, s: DepthReading) -> Outcome:
        """A valid sounding means the transducer floats above the sea bed: corrects s, eta."""
        x = ekf.x
        body, mounts, site = self.vehicle.body, self.vehicle.sensors, self.vehicle.site
        sin_t = math.sin(self.contact.slope_rad)
        floor_depth = x[Idx.S] * sin_t
        h = np.zeros(N_STATES)
        h[Idx.ETA] = 1.0
        if floor_depth < site.sea_floor_depth_m:
            h[Idx.S] = sin_t
        floor_depth = min(floor_depth, site.sea_floor_depth_m)
        predicted = x[Idx.ETA] - body.draft_m + mounts.depth_sounder_z_m + floor_depth
        return ekf.update_scalar(s.depth_m, predicted, h, self.settings.depth_m ** 2,
                                 self.settings.gate_depth, only=WATERLINE_STATE)

    # ------------------------------------------------------------------ track forces
    def track_forces(self, ekf: MotionEkf, s: DriveStatus) -> None:
        """The smoothed track forces against the Wong force of the estimated weight: a
        measurement of the surface (vehicle.md 6), where both tracks turn and slip enough for
        the force to depend on the weight (a stopped or gripping track takes whatever force
        holds it), ``force_update.settle_s`` after a touchdown, and the surface can change
        the force (``_force_per_m``). The slip's uncertainty (the ground speed's and the belt
        speed reading's) joins the force noise."""
        if self.contact.afloat:
            self.grounded_since_s = math.inf
            return
        self.grounded_since_s = min(self.grounded_since_s, s.t_s)
        if not self._force_update_due(s.t_s):
            return
        speeds = (s.port.speed_mps, s.stbd.speed_mps)
        ground = ground_speeds(ekf.x, self.vehicle.body.hull_separation_m)
        held = self._held_sliding(speeds, ground)
        if held:
            speeds = (0.0, 0.0)          # held belts: the encoder's noise is no speed
        elif not self._slipping(speeds, ground):
            return
        measured = [self.contact.measured_soil_force_n(s, k) for k in range(2)]
        if not all(math.isfinite(m) for m in measured):
            return
        self.force_update_t_s = s.t_s
        for k in range(2):
            self._track_force_update(ekf, k, measured[k], speeds[k], ground[k],
                                     self._teaches_soil(held))
        self.bound_by_dry_sensors(ekf, s.t_s)

    def _force_update_due(self, t_s: float) -> bool:
        st = self.settings
        return not (st.force_update_sigma_n <= 0.0
                    or t_s - self.grounded_since_s < st.force_update_settle_s
                    or t_s - self.force_update_t_s < st.force_update_period_s)

    def _held_sliding(self, speeds: tuple[float, float], ground: tuple[float, float]) -> bool:
        """Both belts held while the ground under both moves: each slips at -1, where the
        Wong force is the soil's full shear strength whatever the speeds' errors (a vehicle
        grounding in the surf with its tracks off, carried by the waves)."""
        st = self.settings
        least = st.force_update_held_min_ground_mps
        return least > 0.0 and all(abs(speeds[k]) < st.slip_stopped_track_mps
                                   and abs(ground[k]) >= least for k in range(2))

    def _teaches_soil(self, held: bool) -> bool:
        """Whether this force update may move the soil's strength factor: with the tracks
        carrying ``soil_scale.min_fraction`` of the weight, and not from held belts slid over
        the sand by the waves unless ``soil_scale.from_held_tracks`` (the waves carry a
        vehicle only while they float it nearly off: the weight then is a wave's fleeting
        share the surface estimate lags, and at the slide's speed the saturated sand's
        suction many times its dry strength; the braking force is their product, not a
        lasting property of the sand)."""
        st = self.settings
        return self.contact.fraction >= st.soil_scale_min_fraction and (
            st.soil_scale_from_held_tracks or not held)

    def _slipping(self, speeds: tuple[float, float], ground: tuple[float, float]) -> bool:
        """Both tracks turn fast enough and slip enough for the force to tell the weight."""
        st = self.settings
        slips = [float(traction.slip(speeds[k], ground[k])) for k in range(2)]
        return all(abs(speeds[k]) >= st.force_update_min_track_speed_mps
                   and abs(slips[k]) >= st.force_update_min_slip for k in range(2))

    def _track_force_update(self, ekf: MotionEkf, k: int, measured_n: float, track_mps: float,
                            ground_mps: float, learn_soil: bool) -> None:
        """One track's (0 port, 1 starboard) soil force as a measurement of s and eta (and
        of the soil's strength factor where ``learn_soil``)."""
        st = self.settings
        x, P = ekf.x, ekf.P
        sin_t = math.sin(self.contact.slope_rad)
        half = 0.5 * self.vehicle.body.hull_separation_m
        lever = -half if k == 0 else half
        soil_spread = 0.0
        if st.force_update_max_soil_spread > 0.0:
            soil_spread = self._soil_relative_variance(track_mps, ground_mps)
            if soil_spread > st.force_update_max_soil_spread ** 2:
                return                   # the site's soil is not known well enough yet
        predicted, per_belt_mps, per_ground_mps = self.contact.soil_force_slopes(
            x, x[Idx.S], x[Idx.ETA], track_mps, ground_mps)
        per_m = self._force_per_m(x, predicted, measured_n, track_mps, ground_mps)
        if per_m is None:
            return                       # the surface cannot explain the difference
        ground_var = P[Idx.U, Idx.U] + lever * lever * P[Idx.R, Idx.R] \
            + 2.0 * lever * P[Idx.U, Idx.R]
        slip_var = per_ground_mps * per_ground_mps * max(ground_var, 0.0) \
            + self._belt_speed_variance_n2(track_mps, per_belt_mps)
        if st.force_update_max_slip_spread > 0.0 and math.sqrt(slip_var) \
                > st.force_update_max_slip_spread * max(abs(predicted), abs(measured_n), 1.0):
            return                       # the force says more about the slip than the surface
        h = np.zeros(N_STATES)
        h[Idx.ETA] = per_m
        h[Idx.S] = per_m * sin_t         # the volume follows the water depth eta + s sin
        if x[Idx.SOIL] > 0.0:
            h[Idx.SOIL] = predicted / x[Idx.SOIL]    # the force is the factor x the model's
        var = st.force_update_sigma_n ** 2 + slip_var \
            + soil_spread * max(measured_n * measured_n, predicted * predicted) \
            + (per_m * st.force_update_surface_m) ** 2
        ekf.update_scalar(measured_n, predicted, h, var, st.force_update_gate,
                          only=SURFACE_STATES if learn_soil else WATER_SURFACE_STATES)
        self.clip_soil_scale(ekf)

    def _belt_speed_variance_n2(self, track_mps: float, per_belt_mps: float) -> float:
        """The Wong force's variance from the belt speed's reading (``noise.track_speed_mps``,
        the encoder's noise), N^2, through the force's slope in the belt speed
        ``per_belt_mps`` (N s/m): the slip (v - u) / v is the belt's as much as the ground's,
        and at the surf's small slips a 0.01 m/s error in either moves the force by 10-30 %
        (issue 18, seed 2029's 142: belt read 0.674-0.701 m/s, the model's force at the
        true ground speed 62-120 N against a measured 95-100 N). A held belt (read as 0)
        slips -1 whatever its noise: none."""
        sigma = self.settings.track_speed_sigma_mps
        if sigma <= 0.0 or track_mps == 0.0:
            return 0.0
        return per_belt_mps * per_belt_mps * sigma * sigma

    def clip_soil_scale(self, ekf: MotionEkf) -> None:
        """The soil's strength factor within ``soil_scale.min`` .. ``max`` (the paper's
        fitted soils span about 0.5-1.5 of the 72 % fit's force at the surf's slips)."""
        st = self.settings
        ekf.x[Idx.SOIL] = min(max(ekf.x[Idx.SOIL], st.soil_scale_min), st.soil_scale_max)

    def _soil_relative_variance(self, track_mps: float, ground_mps: float) -> float:
        """The force model's relative variance from the soil's (phi, k) uncertainty: large
        while the site's soil is only the configured prior (a sea-to-land run meets the sand
        in the surf), small once the tracks have learnt it on dry sand (``soil_online``).
        The soil scales the force at a slip about proportionally whatever the weight, so it
        is taken at the full weight."""
        cov = self.contact.soil_cov
        if not np.any(cov):
            return 0.0
        contact, body = self.contact, self.vehicle.body
        weight = 0.5 * contact.weight_n(0.0, False)

        def force(soil) -> float:
            return float(traction.track_force_n(track_mps, ground_mps, weight, soil,
                                                contact.track_area_m2,
                                                body.track_contact_length_m))
        soil = contact.soil
        full = force(soil)
        if abs(full) < 1e-6:
            return 0.0
        jac = np.array([(force(replace(soil, **{name: getattr(soil, name) + step})) - full)
                        / step for name, step in (('friction_angle_rad', SOIL_STEPS[0]),
                                                  ('shear_modulus_m', SOIL_STEPS[1]))])
        return float(jac @ cov @ jac) / (full * full)

    def _force_per_m(self, x: np.ndarray, predicted_n: float, measured_n: float,
                     track_mps: float, ground_mps: float) -> float | None:
        """d force / d surface, N/m; None where the surface cannot change the force.

        Where the estimate puts no weight on the tracks (the volume capped at the
        displacement) the local derivative is nil, and a track clearly pushing under a hull
        thought afloat would be ignored: when the force asks for less water, the secant over
        the first of growing steps down that changes the force is used instead. On dry
        sand (all the weight on the tracks) a force short of the model's says more about the
        soil than about water, and only the local derivative counts.
        """
        less_water = measured_n > predicted_n
        steps, direction = (SECANT_STEPS_M, -1.0) if less_water else (SECANT_STEPS_M[:1], 1.0)
        for step_m in steps:
            moved = self.contact.soil_force_n(x, x[Idx.S], x[Idx.ETA] + direction * step_m,
                                              track_mps, ground_mps)
            if abs(moved - predicted_n) > 1e-3:
                return (moved - predicted_n) / (direction * step_m)
        return None
