"""Contact and submersion: afloat or on the sand, the hulls' volume, the weight on the tracks.

ROS-free. The motion filter (``motion_filter.MotionFilter``) estimates where the vehicle
and the water surface are; this model turns that into what the hulls displace and what the
sand carries (vehicle.md 6), and decides afloat / on the sand from the IMU's motion test,
the track forces and the geometry. Its state (the decision, the weight share, the IMU's
motion filter, the smoothed track forces, the beach slope) changes only when
a sample arrives or the filter advances (``Estimator``), never when someone asks.
"""
from __future__ import annotations

import math

import numpy as np

from dukw_common.vehicle import SoilParams, Vehicle
from dukw_model import buoyancy, traction
from dukw_model.seakeeping import heave_constants
from dukw_estimation.ekf import Idx
from dukw_estimation.force_filter import ForceSmoother
from dukw_common.readings import DriveStatus, ImuSample
from dukw_estimation.settings import EkfSettings

TOUCHDOWN_SHARE = 0.8           # afloat until the mean-surface volume drops below this share
#: hull volumes remembered by their inputs (one sample asks for the same volume several
#: times: the contact decision, the traction output, the force update's prediction)
VOLUME_CACHE_SIZE = 16
DRY_MARGIN_M = 1e-6              # the surface this far below the hulls' bottom line: no volume
# plain ints for the hot paths (indexing numpy with IntEnum members is slower)
_YAW, _U, _R, _S, _ETA = int(Idx.YAW), int(Idx.U), int(Idx.R), int(Idx.S), int(Idx.ETA)
_SOIL = int(Idx.SOIL)


def ground_speeds(x: np.ndarray, hull_separation_m: float) -> tuple[float, float]:
    """Ground speed under the port and starboard tracks, m/s, from the filter's state."""
    half = 0.5 * hull_separation_m
    u, r = x[_U], x[_R]
    return u - r * half, u + r * half


class ContactModel:
    """The afloat / sand decision and the submersion it implies (hull geometry, heave)."""

    def __init__(self, vehicle: Vehicle, settings: EkfSettings, soil: SoilParams) -> None:
        self.vehicle = vehicle
        self.settings = settings
        self.soil = soil
        self.soil_cov = np.zeros((2, 2))   # covariance of (phi, k) of ``soil``, rad, m
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
        self.displaced_m3 = body.displaced_volume_m3     # afloat in calm water (constant)
        # (waterline distance, surface, heading cos, slope) -> grounded volume, m^3; and the
        # last submersion's inputs and (h2, volume)
        self._volumes: dict[tuple[float, ...], float] = {}
        self._submersion: tuple[tuple[float, ...], tuple[float, float]] | None = None
        self._cos_slope = (math.nan, math.nan)    # (slope, its cos), rad
        # (weight, saturation, soil) -> the tracks' patch (``_patch``)
        self._patch_key: tuple | None = None
        self._patch_value: traction.TrackPatch | None = None
        # the heave mass and damping of the hulls' section about the float line (the simulator's)
        heave = heave_constants(body, settings.heave_natural_hz, settings.heave_damping_ratio)
        self.heave_mass_kg = heave.mass_kg
        self.heave_damping_n_per_mps = heave.damping_n_per_mps
        # the most a floating hull's heave acceleration can be, up (the hulls awash: their most
        # buoyancy) and down (none), with the damping at the fastest heave, m/s^2 (inf: off)
        rate = settings.contact_impact_heave_rate_mps
        damping = self.heave_damping_n_per_mps * rate
        rho_g = body.water_density_kgpm3 * body.gravity_mps2
        self.impact_accel_mps2 = (rho_g * self.max_volume_m3 - body.displacement_n + damping) \
            / self.heave_mass_kg if rate > 0.0 else math.inf
        self.drop_accel_mps2 = (body.displacement_n + damping) / self.heave_mass_kg \
            if rate > 0.0 else math.inf
        self.reset()

    def reset(self) -> None:
        """Back to the start: on the sand, all the weight on the tracks, nothing smoothed."""
        st = self.settings
        self.slope_rad = self.vehicle.site.beach_slope_rad
        self.fraction = 1.0
        self.afloat = False
        self.motion_level = 0.0          # > 1: rolling, pitching, heaving like a floating hull
        self.impacts = 0                 # IMU samples taken as the sand striking the keel
        self.force = [ForceSmoother(st.force_process_n_per_s, st.force_measurement_n)
                      for _ in range(2)]
        # per track: ((status, smoothed force), its soil force) last worked out
        self._soil_forces: list[tuple[tuple, float]] = [((None, math.nan), math.nan)] * 2

    # ------------------------------------------------------------------ IMU
    def observe_imu(self, s: ImuSample, heave_accel_mps2: float, dt: float) -> None:
        """The motion test's low-pass, from one IMU sample and base_link's vertical
        acceleration (``MotionFilter.heave_accel_mps2``)."""
        self._update_motion(s, heave_accel_mps2, dt)

    def _update_motion(self, s: ImuSample, heave: float, dt: float) -> None:
        """Low-pass of (roll/pitch rate, heave acceleration) over their thresholds, squared."""
        st = self.settings
        heave = heave if math.isfinite(heave) else 0.0
        if self.impact(heave):
            # the sand striking the keel: not floating motion, and the hull is on the sand now
            self.impacts += 1
            self.motion_level = 0.0
            return
        level = ((s.roll_rate_rps ** 2 + s.pitch_rate_rps ** 2) / st.contact_rate_rps ** 2
                 + heave ** 2 / st.contact_accel_mps2 ** 2)
        alpha = min(dt / st.contact_time_constant_s, 1.0) if dt > 0.0 else 1.0
        self.motion_level += alpha * (level - self.motion_level)

    def impact(self, heave_accel_mps2: float) -> bool:
        """A heave acceleration no floating hull can have (beyond what the buoyancy of the
        hulls awash, or of none, and the damping at ``contact.impact_heave_rate_mps`` give):
        the sand striking the keel, or its rebound."""
        return heave_accel_mps2 > self.impact_accel_mps2 \
            or heave_accel_mps2 < -self.drop_accel_mps2

    def update_slope(self, s: ImuSample, yaw_rad: float, dt: float) -> None:
        """Low-pass the beach slope along the seaward direction from pitch and roll, while
        the hull lies on the sand: the contact decision says so, the IMU's motion test is
        under a floating hull's level (1: no floating roll, pitch or heave) and the tracks
        carry at least ``slope.min_fraction`` of the weight. A hull resting on its tracks
        has the beach's pitch whatever the water carries of it; a floating one has the
        waves'."""
        if self.afloat or self.motion_level > 1.0 \
                or self.fraction < self.settings.slope_min_fraction:
            return
        rel = yaw_rad - self.settings.seaward_yaw_rad
        measured = s.pitch_rad * math.cos(rel) + s.roll_rad * math.sin(rel)
        alpha = min(dt / self.settings.slope_time_constant_s, 1.0)
        self.slope_rad += alpha * (measured - self.slope_rad)

    def track_end_drop_m(self, s: ImuSample, yaw_rad: float) -> float:
        """How far the lowest point of the tracks hangs below base_link (the keel's middle),
        m (``traction.track_end_drop_m``) for the hull's pitch and roll (the IMU's) against
        the estimated beach's under it. A hull meets the beach with that point first: afloat
        it pitches with the waves, and grazing the sand it rests on it. A hull lying still
        (the IMU's motion test under a floating hull's level, 1) lies on its tracks: none
        (its pitch is the beach's, which the estimated slope may not yet be)."""
        if self.motion_level <= 1.0:
            return 0.0
        rel = yaw_rad - self.settings.seaward_yaw_rad
        body = self.vehicle.body
        return traction.track_end_drop_m(body.track_contact_length_m, body.hull_separation_m,
                                         s.pitch_rad - self.slope_rad * math.cos(rel),
                                         s.roll_rad - self.slope_rad * math.sin(rel))

    # ------------------------------------------------------------------ tracks
    def smooth_track_forces(self, s: DriveStatus) -> None:
        """Each track's force (measured, else current x gain) into its smoother."""
        gain = self.vehicle.drivetrain.track_force_gain_n_per_a
        for smoother, side in zip(self.force, (s.port, s.stbd), strict=True):
            force = side.force_n if math.isfinite(side.force_n) else side.current_a * gain
            smoother.update(s.t_s, force)

    def measured_soil_force_n(self, tracks: DriveStatus | None, k: int) -> float:
        """Track k's (0 port, 1 starboard) smoothed current x gain less the drivetrain's own
        friction (no-load current, belt), which opposes the belt, not the sand: the soil's
        force, N (NaN before a status). The friction fades in over the first
        ``drivetrain.friction_fade_mps`` of belt speed, as in the simulator."""
        force = self.force[k].force_n
        if tracks is None or not math.isfinite(force):
            return math.nan
        key = (tracks, force)
        known = self._soil_forces[k]
        if known[0] == key:              # the same status and smoothed force: the same value
            return known[1]
        speed = (tracks.port, tracks.stbd)[k].speed_mps
        drive = self.vehicle.drivetrain
        fade = math.tanh(speed / drive.friction_fade_mps)
        value = force - drive.track_friction_n(k == 0) * fade
        self._soil_forces[k] = (key, value)
        return value

    def tracks_pushing(self, tracks: DriveStatus | None, tracks_fresh: bool) -> bool:
        """Both tracks push or brake the vehicle harder than water could (paddling belts,
        a held belt's drag): on the sand. From the smoothed forces less the drivetrain
        friction, fresh status only; a held (stopped) belt braking counts as well."""
        st = self.settings
        if st.contact_track_force_n <= 0.0 or tracks is None or not tracks_fresh:
            return False
        limit = st.contact_track_force_n
        return (abs(self.measured_soil_force_n(tracks, 0)) >= limit
                and abs(self.measured_soil_force_n(tracks, 1)) >= limit)

    # ------------------------------------------------------------------ submersion
    def submersion(self, x: np.ndarray) -> tuple[float, float]:
        """(h2, the volume the estimated surface puts under water on the slope), m, m^3."""
        waterline, eta, yaw = x.item(_S), x.item(_ETA), x.item(_YAW)   # floats: the same
        key = (waterline, eta, yaw, self.slope_rad)       # (the heading's cos on a miss only)
        last = self._submersion
        if last is not None and last[0] == key:
            return last[1]
        heading_cos = math.cos(yaw - self.settings.seaward_yaw_rad)
        line = self._bottom_line(waterline, eta, heading_cos)
        h2 = buoyancy.submerged_length_of_line_m(*line, self.hull_bow_x_m, self.hull_stern_x_m)
        value = (h2, self.grounded_volume_m3(waterline, eta, heading_cos, line))
        self._submersion = (key, value)
        return value

    def _bottom_line(self, waterline_distance_m: float, surface_m: float,
                     heading_cos: float) -> tuple[float, float]:
        """``buoyancy.bottom_depth_line`` on the estimated slope: the water over the hulls'
        bottom line at base_link and its gradient along the body."""
        return buoyancy.bottom_depth_line(waterline_distance_m, self.slope_rad,
                                          self.vehicle.body.hull_clearance_m, surface_m,
                                          heading_cos)

    def grounded_volume_m3(self, waterline_distance_m: float, surface_m: float,
                           heading_cos: float, line: tuple[float, float] | None = None
                           ) -> float:
        """The hulls' volume under the surface ``surface_m`` with the waterline this far,
        on the estimated slope, m^3 (``buoyancy.grounded_volume_m3``, remembered by its
        inputs: the same value, computed once). ``line``: their ``_bottom_line`` if the
        caller has it."""
        key = (waterline_distance_m, surface_m, heading_cos, self.slope_rad)
        volumes = self._volumes
        volume = volumes.get(key)
        if volume is None:
            if len(volumes) >= VOLUME_CACHE_SIZE:
                volumes.clear()
            if line is None:
                line = self._bottom_line(waterline_distance_m, surface_m, heading_cos)
            if self._dry(*line):
                volume = volumes[key] = 0.0
            else:
                volume = volumes[key] = buoyancy.grounded_volume_of_line_m3(
                    *line, self.hull_bow_x_m, self.hull_stern_x_m, self.section)
        return volume

    def _dry(self, depth0_m: float, gradient: float) -> bool:
        """The surface clearly (``DRY_MARGIN_M``) below both ends of the hulls' bottom line
        (``_bottom_line``): ``buoyancy.grounded_volume_m3`` would integrate nothing and
        return 0.0 (on the sand, most samples)."""
        deepest = max(depth0_m + gradient * self.hull_bow_x_m,
                      depth0_m + gradient * self.hull_stern_x_m)
        return deepest < -DRY_MARGIN_M

    def surface_volume_m3(self, x: np.ndarray, raise_m: float = 0.0) -> float:
        """The volume under a surface ``raise_m`` above the estimated one, m^3 (0: dry)."""
        heading_cos = math.cos(x[_YAW] - self.settings.seaward_yaw_rad)
        return self.grounded_volume_m3(x[_S], x[_ETA] + raise_m, heading_cos)

    def weight_n(self, grounded_volume_m3: float, afloat: bool) -> float:
        """Weight on the tracks, N: none afloat; on the sand the hulls do not float."""
        if afloat:
            return 0.0
        return self._effective_weight_n(min(grounded_volume_m3, self.displaced_m3))

    def _effective_weight_n(self, volume_m3: float) -> float:
        """``traction.effective_weight_n`` on the estimated slope for one volume, written
        for a scalar (the same operations in the same order: the same bits; numpy's cos of
        the slope, remembered while the slope stays)."""
        body = self.vehicle.body
        if self._cos_slope[0] != self.slope_rad:
            self._cos_slope = (self.slope_rad, float(np.cos(self.slope_rad)))
        buoyancy_n = body.water_density_kgpm3 * body.gravity_mps2 * float(volume_m3)
        return max(body.displacement_n - buoyancy_n, 0.0) * self._cos_slope[1]

    def fraction_of(self, weight_n: float) -> float:
        """The share of the weight (along the slope's normal) the tracks carry."""
        return weight_n / (self.vehicle.body.displacement_n * math.cos(self.slope_rad))

    def floating(self, grounded_volume_m3: float, imu_fresh: bool, pushing: bool) -> bool:
        """Afloat or on the sand: the IMU's motion test when fresh, else the geometry.

        Deep enough water (the estimated surface gives the displacement; with hysteresis: once
        afloat, the hulls must sit clearly shallower to touch down) floats it. In the surf, the
        IMU tells: on the sand the vehicle lies on the beach (no roll/pitch rate, no heave
        acceleration); floating, it rolls, pitches and heaves with the waves. Both tracks
        pushing hard (``tracks_pushing``) mean the sand.
        """
        displaced = self.displaced_m3
        if pushing:
            return False
        limit = displaced * (TOUCHDOWN_SHARE if self.afloat else 1.0)
        if grounded_volume_m3 >= limit:
            # deep enough to float even in calm water - unless the IMU says the vehicle lies
            # still on the sand, in a trough the estimated surface does not show
            return not imu_fresh or self.motion_level > 1.0 \
                or grounded_volume_m3 >= self.sure_float_m3
        if imu_fresh:
            return self.motion_level > 1.0 and \
                grounded_volume_m3 >= self.settings.contact_min_volume_share * displaced
        return False

    def refresh(self, x: np.ndarray, imu_fresh: bool, pushing: bool) -> None:
        """Decide afloat or on the sand and the weight share for the filter's state ``x``."""
        _, grounded = self.submersion(x)
        self.afloat = self.floating(grounded, imu_fresh, pushing)
        self.fraction = self.fraction_of(self.weight_n(grounded, self.afloat))

    def afloat_volume_m3(self, heave_accel_mps2: float, heave_rate_mps: float,
                         imu_fresh: bool) -> float:
        """Floating: the displacement, plus what the heave acceleration and the damping force
        of the heave rate say (IMU fresh)."""
        body = self.vehicle.body
        if not math.isfinite(heave_accel_mps2) or not imu_fresh:
            return body.displaced_volume_m3
        volume = buoyancy.afloat_dynamic_volume_m3(
            body.displacement_n + self.heave_damping_n_per_mps * heave_rate_mps,
            self.heave_mass_kg, heave_accel_mps2, body.water_density_kgpm3, body.gravity_mps2)
        return min(max(volume, 0.0), self.max_volume_m3)

    def soil_force_n(self, x: np.ndarray, waterline_distance_m: float, surface_m: float,
                     track_mps: float, ground_mps: float) -> float:
        """Soil force on the vehicle from one track at these speeds, with the weight the
        surface leaves it and the filter's soil strength factor, N (heading from ``x``)."""
        patch = self._surface_patch(x, waterline_distance_m, surface_m)
        return x[_SOIL] * traction.track_force_f(patch, track_mps, ground_mps)

    def soil_force_slopes(self, x: np.ndarray, waterline_distance_m: float, surface_m: float,
                          track_mps: float, ground_mps: float) -> tuple[float, float, float]:
        """``soil_force_n`` (the same bits) and its analytic slopes in the belt's and the
        ground's speeds: (force N, d force / d track speed N s/m, d force / d ground speed
        N s/m), from ``traction.track_force_slopes_f``."""
        patch = self._surface_patch(x, waterline_distance_m, surface_m)
        force, per_track, per_ground = traction.track_force_slopes_f(patch, track_mps,
                                                                     ground_mps)
        factor = x[_SOIL]
        return factor * force, factor * per_track, factor * per_ground

    def _surface_patch(self, x: np.ndarray, waterline_distance_m: float,
                       surface_m: float) -> traction.TrackPatch:
        """One track's patch with the weight and the saturation this surface leaves it."""
        heading_cos = math.cos(x[_YAW] - self.settings.seaward_yaw_rad)
        volume = self.grounded_volume_m3(waterline_distance_m, surface_m, heading_cos)
        weight = self._effective_weight_n(min(volume, self.vehicle.body.displaced_volume_m3))
        return self._patch(0.5 * weight, self.saturation(waterline_distance_m, surface_m,
                                                         heading_cos))

    def saturation(self, waterline_distance_m: float, surface_m: float,
                   heading_cos: float) -> float:
        """Share of the tracks' patches with water over the sand (the estimated surface
        ``surface_m`` over a beach of the estimated slope), 0..1: saturated sand."""
        sin_t = math.sin(self.slope_rad)
        return traction.saturated_share(surface_m + waterline_distance_m * sin_t,
                                        heading_cos * sin_t,
                                        self.vehicle.body.track_contact_length_m)

    def track_force_n(self, track_mps: float, ground_mps: float, weight_n: float,
                      saturation: float) -> float:
        """The shared traction model's soil force of one track carrying ``weight_n`` on sand
        this much saturated (the saturated sand's pore suction, ``vehicle.saturated_sand``), N."""
        return traction.track_force_f(self._patch(weight_n, saturation), track_mps, ground_mps)

    def _patch(self, weight_n: float, saturation: float) -> traction.TrackPatch:
        """One track's patch at this weight and saturation on the present soil
        (``traction.track_force_f``: the same bits as ``track_force_n``), remembered while
        they hold: both tracks' forces and slopes at one surface ask for the same one."""
        key = (weight_n, saturation, self.soil)
        if self._patch_key != key:
            self._patch_key = key
            self._patch_value = traction.TrackPatch(
                weight_n, self.soil, self.track_area_m2,
                self.vehicle.body.track_contact_length_m, self.vehicle.saturated_sand,
                saturation)
        return self._patch_value
