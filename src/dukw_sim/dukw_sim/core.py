"""SimCore: the DUKW-Ling's physics on sand, in the surf and afloat (ROS-free).

State: planar rigid body (x, y, yaw; surge, sway, yaw rate) plus heave, roll and
pitch of the centre of gravity, the two track drives' speed loops and whether the
tracks touch the ground. One fixed step of ``dt_s`` (semi-implicit Euler). The soil
forces are stiff (on firm sand the Wong force goes from nothing to full strength
within a few per cent of slip), so surge and yaw rate are solved implicitly with them
(Newton passes, motor limits as caps); where that does not converge or a slip would
change sign within the step (starting, stopping on firm sand) the tracks grip: the
step moves the ground under the tracks at the tracks' speeds, with forces capped by
the soil's strength and the motors.

Vertical motion: on the ground the vehicle follows the beach (its tracks carry the
effective weight W_e = (Delta - rho g V) cos theta); when the buoyancy of the hull
strips against the instantaneous surface exceeds the weight it lifts off and heaves,
rolls and pitches freely until a track end touches the sand again. So in the surf the
tracks touch intermittently and the traction comes and goes.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping, NamedTuple

import numpy as np

from dukw_common.config import ParamValue, node_params
from dukw_common.vehicle import SoilParams, Vehicle
from dukw_model import traction
from dukw_model.propeller import prop_thrust_n, propeller_thrust_factor

from dukw_sim.forces import (LATERAL_POINTS, BodyForces, Immersion, StripSums, WaveForcing,
                             WaveMoments, drivetrain_friction_n, hydrodynamic_drag, immersion,
                             lateral_resistance, odom_force, paddle_wrench, propulsion,
                             rolling_resistance, saturated_share, slope_gravity, strip_basis,
                             strip_sums, strip_yaw_added_inertia_kg_m2,
                             sum_wrenches, surf_resistance, track_paddle_n, track_wetness,
                             water_yaw_rate_rps, wave_forcing, wave_moments)
from dukw_sim.hull import HullGeometry, Seakeeping
from dukw_sim.land import (TrackContact, TrackLinear, belt_equivalent_mass_kg, belt_mass_kg,
                           inertial_loop, linearise, motor_limited_speed, predicted_speeds)
from dukw_sim.params import SimParams, apply_overrides
from dukw_sim.truth import Medium, Truth
from dukw_sim.world import (Beach, WaterSample, WaveModel, World, irregular_waves, no_waves,
                            regular_waves)
from dukw_model.fast_numpy import dot as _dot, new_tuple as _new_tuple, sum_of as _sum_of

__all__ = ['Actuation', 'SimCore', 'SimParams']

_LAND_FRACTION = 0.02          # submerged share of the afloat volume below which: LAND
_NEWTON_PASSES = 3             # implicit track-soil solve
_NEWTON_TOL_MPS = 2e-4
_CLEAR_MARGIN_M = 1e-9          # touchdown's shortcut: clear of the sand by more than this
_SLIDING = 2                    # a limited track at the soil's strength (the motor's: +-1)


class TrackState(NamedTuple):
    """Both tracks after a step (port, starboard): speed, soil force, motor force, slip."""

    track_speed_mps: list
    soil_force_n: list
    motor_force_n: list
    slip: list


class _Drives(NamedTuple):
    """The track drives during a step, before the soil forces are solved for."""

    ground: tuple                # speed of the ground under each track, m/s (body surge)
    others: list                 # motor force besides the soil's: friction + paddling, N
    paddle: list                 # the tracks' paddle force on the vehicle, N
    loop_k: tuple                # speed loop with the belt's inertia over the step: its
                                 # stiffness, N per m/s (inf: holds its speed) ...
    loop_ref: tuple              # ... and its reference, m/s (land.inertial_loop)
    motor_map: tuple             # the motor's force for a load L on the loop: g L + b, per
                                 # track (g_p, b_p, g_s, b_s): the belt's acceleration added
    contact: TrackContact | None
    lin: TrackLinear             # the soil forces linearised at the step's ground speeds


class _Hydro(NamedTuple):
    """The water at the sample points and the strips' immersion for one pose (cached)."""

    px: np.ndarray               # odom x of the sample points (then of the kinematic rows)
    water: WaterSample
    depths: np.ndarray           # water over each strip's bottom, m
    areas: np.ndarray            # each strip's immersed section, m^2
    sums: StripSums              # their area-weighted sums


class _Stepped(NamedTuple):
    """What a step leaves for the Truth beyond the state (NamedTuples: made every step)."""

    tracks: TrackState
    thrust_n: list
    w_eff_n: float
    wave_fx_n: float             # wave force on the hull, odom
    wave_fy_n: float
    accel: tuple                 # surge, sway, heave acceleration, m/s^2


@dataclass(frozen=True)
class Actuation:
    """What reaches the motor controllers, after the servo switch, % of full scale."""

    port_track_pct: float = 0.0
    stbd_track_pct: float = 0.0
    port_prop_pct: float = 0.0
    stbd_prop_pct: float = 0.0

    def validated(self) -> 'Actuation':
        """Return self; raise ValueError on a non-finite or out-of-range command."""
        for name in ('port_track_pct', 'stbd_track_pct', 'port_prop_pct', 'stbd_prop_pct'):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f'actuation {name} must be a finite number, got {value!r}')
            if abs(value) > 100.0:
                raise ValueError(f'actuation {name} must be within +-100 %, got {value}')
        return self


def _require_finite(what: str, *values: float) -> None:
    if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in values):
        raise ValueError(f'{what} must be finite numbers, got {values}')


def _soil_with_floor(soil: SoilParams, min_k_m: float) -> SoilParams:
    return SoilParams(soil.cohesion_pa, soil.friction_angle_rad,
                      max(soil.shear_modulus_m, min_k_m))


def _make_world(vehicle: Vehicle, params: SimParams, rng: np.random.Generator) -> World:
    beach = Beach(vehicle.site.beach_slope_rad, vehicle.site.sea_floor_depth_m,
                  params.world.flat_start_x_m)
    w = params.waves
    if w.model == WaveModel.REGULAR and w.significant_height_m > 0.0:
        waves = regular_waves(w.significant_height_m, w.peak_period_s, w.reference_depth_m)
    elif w.model == WaveModel.IRREGULAR and w.significant_height_m > 0.0:
        waves = irregular_waves(w.significant_height_m, w.peak_period_s, w.reference_depth_m,
                                rng, w.components, w.jonswap_gamma, w.spreading_rad,
                                w.mean_direction_rad, w.spreading_exponent_s, w.directions,
                                w.spreading_by_frequency)
    else:
        waves = no_waves()
    return World(beach, waves, w.breaking_ratio, w.reference_depth_m, w.second_order)


def _loaded_speed(loop_ref_mps: float, force_n: float, loop_k: float) -> float:
    """Track speed of a speed loop (not at its current limit) giving this force to the soil
    and the drivetrain's friction, m/s (with the belt's inertia: land.inertial_loop)."""
    if math.isinf(loop_k):
        return loop_ref_mps
    return loop_ref_mps - force_n / loop_k      # afloat too: friction, paddling


def _grip_forces(a: float, b: float, rhs: list, comp: list, fixed: list) -> list[float]:
    """The two tracks' soil forces of the grip step: (a + b + c_i) F_i + (a - b) F_j =
    rhs_i for each track whose force is not ``fixed`` (None), N."""
    own, cross = [a + b + comp[0], a + b + comp[1]], a - b
    if fixed[0] is not None and fixed[1] is not None:
        return list(fixed)
    if fixed[0] is not None:
        return [fixed[0], (rhs[1] - cross * fixed[0]) / own[1]]
    if fixed[1] is not None:
        return [(rhs[0] - cross * fixed[1]) / own[0], fixed[1]]
    det = own[0] * own[1] - cross * cross
    return [(rhs[0] * own[1] - cross * rhs[1]) / det, (own[0] * rhs[1] - cross * rhs[0]) / det]


class SimCore:
    """The vehicle in its world, advanced one fixed step at a time."""

    def __init__(self, vehicle: Vehicle, params: SimParams, seed: int = 0) -> None:
        self.vehicle = vehicle
        self.params = params
        self.seed = int(seed)
        self.dt_s = params.dt_s
        self.rng = np.random.default_rng(self.seed)
        self.world = _make_world(vehicle, params, self.rng)
        self.hull = HullGeometry.from_vehicle(vehicle, params.world.hull_stations)
        self.seakeeping = Seakeeping.calibrate(self.hull, vehicle, params.seakeeping)
        body, drive, land = vehicle.body, vehicle.drivetrain, params.land
        self._mass = body.mass_kg
        self._weight = body.displacement_n
        self._rho_g = body.water_density_kgpm3 * body.gravity_mps2
        self._g = body.gravity_mps2
        self._afloat_volume = body.displaced_volume_m3
        self._half_sep = body.hull_separation_m / 2.0
        self._track_len = body.track_contact_length_m
        self._track_area = body.track_width_m * body.track_contact_length_m
        self._kg = body.kg_m
        self._max_motor_n = drive.track_force_gain_n_per_a * (
            land.max_current_a - drive.no_load_current_a)
        self._port_droop_mps = (land.port_speed_deficit_pct / 100.0
                                * drive.full_scale_track_speed_mps)
        droop = land.speed_loop_droop_mps_per_kn / 1000.0       # m/s per N
        self._loop_k = 1.0 / droop if droop > 0.0 else math.inf   # N per m/s
        # each drive's inertia at the belt, and that inertia over one implicit step, N per m/s
        self._belt_mass_kg = belt_equivalent_mass_kg(
            land.motor_rotor_inertia_kg_m2, drive.gear_reduction, drive.sprocket_diameter_m,
            belt_mass_kg(land.belt_mass_per_area_kgpm2, body.track_width_m,
                         body.track_contact_length_m, drive.sprocket_diameter_m),
            land.track_wheels_inertia_kg_m2)
        self._belt_n_per_mps = self._belt_mass_kg / self.dt_s
        self._wet_soil = _soil_with_floor(vehicle.soil, land.min_shear_modulus_m)
        dry = params.dry_soil or vehicle.soil
        self._dry_soil = _soil_with_floor(dry, land.min_shear_modulus_m)
        self._suction = vehicle.saturated_sand
        # the sea state's wave height (H or Hs): the surf's liquefaction of the sand
        self._wave_height_m = 0.0 if self.world.calm else params.waves.significant_height_m
        s = vehicle.sensors
        n = self.hull.station_x_m.size
        self._n_stations = n
        # body-frame sample points: hull strips, then base_link, fore, aft sensors, sounder,
        # port and starboard propeller hubs (on the hulls' centrelines)
        prop = params.propeller
        self._pts_x = np.concatenate([self.hull.station_x_m,
                                      [0.0, s.fore_water_x_m, s.aft_water_x_m,
                                       s.depth_sounder_x_m, prop.x_m, prop.x_m]])
        self._pts_y = np.concatenate([self.hull.station_y_m,
                                      [0.0, 0.0, 0.0, 0.0, self._half_sep, -self._half_sep]])
        self._pts_rows = self.world.rigid_rows(self._pts_x, self._pts_y, n)
        self._lat_s = [self._track_len * ((j + 0.5) / LATERAL_POINTS - 0.5)
                       for j in range(LATERAL_POINTS)]
        # strips over the tracks' contact length: where the surf wets the tracks
        self._track_strips = np.flatnonzero(np.abs(self.hull.station_x_m)
                                            <= self._track_len / 2.0)
        self._wave_lever_z = params.wave_moments.transverse_force_z_m - self._kg
        # Morison C_m = 1 + C_a across the hulls too (waves.moments.sway_inertia_from_added_mass)
        self._sway_inertia_coeff = (1.0 + params.water.sway_added_mass_ratio
                                    if params.wave_moments.sway_inertia_from_added_mass
                                    else None)
        self._no_moments = WaveMoments(0.0, 0.0, 0.0)
        self._external = (0.0, 0.0, 0.0)
        self._valid_act: Actuation | None = None
        self._open_water_of: Actuation | None = None     # the propellers' open-water thrust
        self._open_water = (0.0, 0.0)
        self._hydro_key = None
        self._hydro_val = None
        self._ground_key = None
        self._ground_val = None
        self._over_tracks_of = None
        self._over_tracks = None
        # the water's rotation the yaw damping acts against: each strip's cross-flow weighted
        # by the sway drag, its along-hull flow by the surge drag (waves.moments.*)
        wat = params.water
        self._surge_to_sway_drag = (
            wat.surge_linear_drag_n_per_mps / wat.sway_linear_drag_n_per_mps
            if params.wave_moments.water_rotation_by_drag
            and wat.sway_linear_drag_n_per_mps > 0.0 else 1.0)
        # yaw added inertia afloat from the hull strips (the sway added mass along them)
        self._yaw_added_inertia = strip_yaw_added_inertia_kg_m2(
            wat.sway_added_mass_ratio * self._mass, self.hull.station_x_m)
        # the strips' rows 1, x, y, x^2, y^2: their area-weighted sums (forces.strip_sums)
        self._strip_basis = strip_basis(self.hull.station_x_m, self.hull.station_y_m)
        self._strip_tilt = np.column_stack([-self.hull.station_x_m, self.hull.station_y_m])
        self._tilt_sines = np.zeros(2)
        self._bottom_operand = np.zeros(())
        self._wave_a2 = float(np.sum(self.world.waves.amplitude_m ** 2))
        self.reset()

    @classmethod
    def from_config(cls, path=None, overrides: Mapping[str, ParamValue] | None = None,
                    seed: int = 0) -> 'SimCore':
        """Build from the parameter file (shared block + sim_node block) and dotted overrides."""
        params = apply_overrides(node_params('sim_node', path), overrides)
        return cls(Vehicle.from_params(params), SimParams.from_params(params), seed)

    # ----------------------------------------------------------------- reset / helpers
    def start_x_m(self, start: str) -> float:
        """Where a named start is along the beach, m (``start.*``; the one definition the
        maneuvers, the evaluation and the campaigns use): 'sand', 'surf', 'afloat'; 'flat'
        (flat sand clear of the slope) and 'sea' (just afloat off the slope)."""
        st = self.params.start
        if start == 'flat':
            return self.params.world.flat_start_x_m - st.land_clearance_m
        if start == 'sea':
            depth_m = self.vehicle.body.draft_m + st.sea_tread_clearance_m
            return depth_m / math.tan(self.vehicle.site.beach_slope_rad)
        starts = {'sand': st.sand_x_m, 'surf': st.surf_x_m, 'afloat': st.afloat_x_m}
        if start not in starts:
            raise ValueError(f'start must be one of {sorted([*starts, "flat", "sea"])}, '
                             f'got {start!r}')
        return starts[start]

    def reset(self, start: str = 'sand', x_m: float | None = None,
              yaw_rad: float = 0.0) -> Truth:
        """Put the vehicle at rest at a named start (``start_x_m``) or at x_m."""
        if x_m is None:
            x_m = self.start_x_m(start)
        _require_finite('reset position and yaw', x_m, yaw_rad)
        self.t_s = 0.0
        self.x, self.y, self.yaw = float(x_m), 0.0, float(yaw_rad)
        self.u = self.v = self.r = 0.0
        self.heave_vel = self.roll_rate = self.pitch_rate = 0.0
        self.ref = [0.0, 0.0]
        self.track_speed = [0.0, 0.0]
        self._external = (0.0, 0.0, 0.0)
        gz, gpitch, groll, _ = self._ground_pose()
        self.z_cg, self.pitch, self.roll = gz + self._kg, gpitch, groll
        self.in_contact = True
        self.grazing = False
        if self._grounded_buoyancy() >= self._weight:
            self.in_contact = False
            self.z_cg = self._float_height()
            self.pitch = self.roll = 0.0
        self._step_pose = (self.z_cg, self.pitch, self.roll, self.in_contact)   # (step's)
        self.truth = self._compute_truth(Actuation(), None)
        return self.truth

    def perturb(self, heave_m: float = 0.0, roll_rad: float = 0.0,
                pitch_rad: float = 0.0) -> Truth:
        """Displace a floating vehicle from where it is (a free-decay test); ValueError on land."""
        _require_finite('perturbation', heave_m, roll_rad, pitch_rad)
        if self.in_contact:
            raise ValueError('perturb needs the vehicle afloat (tracks off the ground)')
        self.z_cg += heave_m
        self.roll += roll_rad
        self.pitch += pitch_rad
        self.truth = self._compute_truth(Actuation(), None)
        return self.truth

    def set_external_force(self, fx_n: float = 0.0, fy_n: float = 0.0,
                           yaw_moment_nm: float = 0.0) -> None:
        """A horizontal force on the vehicle in odom (a tow line, a hand holding it), N."""
        _require_finite('external force', fx_n, fy_n, yaw_moment_nm)
        self._external = (float(fx_n), float(fy_n), float(yaw_moment_nm))

    def _ground_pose(self) -> tuple[float, float, float, float]:
        """Ground height at base_link, pitch and roll of a vehicle resting on it, slope
        (remembered for the last position and heading: a step asks at its end and the next
        one at its start)."""
        key = (self.x, self.yaw)
        if key == self._ground_key:
            return self._ground_val
        self._ground_val = self._ground_pose_at()
        self._ground_key = key
        return self._ground_val

    def _ground_pose_at(self) -> tuple[float, float, float, float]:
        beach = self.world.beach
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        half = self._track_len / 2.0
        front = beach.height_m(self.x + c * half)
        rear = beach.height_m(self.x - c * half)
        left = beach.height_m(self.x - s * self._half_sep)
        right = beach.height_m(self.x + s * self._half_sep)
        pitch = math.atan2(rear - front, self._track_len)
        roll = math.atan2(left - right, 2.0 * self._half_sep)
        grad = beach.gradient(self.x)
        return 0.5 * (front + rear), pitch, roll, math.atan(abs(grad))

    def _strip_depths(self, eta: np.ndarray, z_cg: float, pitch: float,
                      roll: float) -> np.ndarray:
        # eta - (z_cg + bottom - x sin(pitch) + y sin(roll)): one product for the tilt
        tilt = self._tilt_sines                  # (sin(pitch), sin(roll)), kept as an array
        tilt[0], tilt[1] = math.sin(pitch), math.sin(roll)
        depths = eta[:self._n_stations] - _dot(self._strip_tilt, tilt)   # dot: matmul's bits
        bottom = self._bottom_operand             # a 0-d array (fast_numpy.operand)
        bottom[()] = z_cg + self.hull.bottom_above_cg_m
        depths -= bottom
        return depths

    def _hydro(self) -> _Hydro:
        """Water at the sample points and the strips' immersion for the current pose (cached)."""
        key = (self.t_s, self.x, self.y, self.yaw, self.z_cg, self.pitch, self.roll)
        if self._hydro_key == key:
            return self._hydro_val
        px, water = self.world.sample_rigid(self._pts_rows, self._pts_x.size, self.x, self.y,
                                            math.cos(self.yaw), math.sin(self.yaw), self.t_s,
                                            self.z_cg + self.hull.axis_above_cg_m)
        depths = self._strip_depths(water.elevation_m, self.z_cg, self.pitch, self.roll)
        areas = self.hull.areas_m2(depths)
        self._hydro_key = key
        self._hydro_val = _new_tuple(_Hydro, (px, water, depths, areas,
                                              strip_sums(areas, water, self._strip_basis)))
        return self._hydro_val

    def _grounded_buoyancy(self) -> float:
        """Buoyancy of the hull at the current pose (the ground's, set by the caller to see
        whether the water would lift it), N: the surface at the strips alone (no kinematics)
        and the strips' area sum as ``strip_sums`` gives it (the same bits as ``_hydro``)."""
        n = self._n_stations
        _, water = self.world.sample_rigid(self._pts_rows, self._pts_x.size, self.x, self.y,
                                           math.cos(self.yaw), math.sin(self.yaw), self.t_s,
                                           0.0, kinematics=False)
        areas = self.hull.areas_m2(self._strip_depths(water.elevation_m, self.z_cg, self.pitch,
                                                      self.roll))
        still = np.zeros(n)                       # kinematics that do not enter the area sum
        sums = strip_sums(areas, _new_tuple(WaterSample, (water.elevation_m, still, still,
                                                          still, still)), self._strip_basis)
        return self._rho_g * sums.area_m2 * self.hull.strip_length_m

    def _float_height(self) -> float:
        """Centre-of-gravity height at which the level hull floats on the current surface."""
        water = self._hydro().water
        lo, hi = -5.0, 5.0
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            depths = self._strip_depths(water.elevation_m, mid, 0.0, 0.0)
            b = self._rho_g * float(np.sum(self.hull.areas_m2(depths))) * self.hull.strip_length_m
            if b > self._weight:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi)

    # ----------------------------------------------------------------------- step
    def step(self, act: Actuation) -> Truth:
        """Advance one step of dt_s with the commands ``act``; return the new Truth."""
        if act is not self._valid_act:         # frozen: a command checked once stays valid
            if not isinstance(act, Actuation):
                raise ValueError(f'step needs an Actuation, got {type(act).__name__}')
            self._valid_act = act.validated()
        dt = self.dt_s
        u0, v0, hv0 = self.u, self.v, self.heave_vel
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        grounded = self.in_contact or self.grazing
        imm, w_eff, hydro = self._contact_and_immersion()
        # the pose at the step's start and whether the hull touched the sand then (lying on
        # it or grazing it): a touchdown's rates within the step follow (_touchdown_rates)
        self._step_pose = (self.z_cg, self.pitch, self.roll, grounded)
        _, water, depths, areas, sums = hydro
        body = self.vehicle.body
        waves = wave_forcing(self.world.calm, areas, self.hull.strip_length_m, water,
                             self.params.waves, body.water_density_kgpm3, self._rho_g,
                             self._wave_a2, body.beam_m, imm, sums)
        # water velocity in body axes
        uw = c * waves.water_u_mps + s * waves.water_v_mps
        vw = -s * waves.water_u_mps + c * waves.water_v_mps
        u_rel, v_rel = u0 - uw, v0 - vw
        r_rel = self.r - self._water_yaw_rate(areas, water, (c, s), sums)
        drives = self._track_drives(act, u_rel, w_eff, depths)
        thrust = self._thrust_n(act, water.elevation_m)
        moments = self._wave_moments(areas, water, (c, s), sums)
        if moments.extra_fy_n or moments.extra_fx_n:   # the strips' sway inertia coefficient
            waves = _new_tuple(WaveForcing, (waves.fx_n + moments.extra_fx_n,   # _replace
                                             waves.fy_n + moments.extra_fy_n,
                                             waves.water_u_mps, waves.water_v_mps))
        forces = self._body_forces(drives, imm, waves, thrust, w_eff, (u_rel, v_rel, r_rel),
                                   (c, s), moments.yaw_nm)
        tracks = self._integrate_plane(forces, drives, imm.fraction, (c, s))
        if self.in_contact:
            self._follow_ground()
        else:
            self._float_free(imm, moments, sums)
        self.t_s += dt
        accel = ((self.u - u0) / dt - self.r * self.v, (self.v - v0) / dt + self.r * self.u,
                 (self.heave_vel - hv0) / dt)
        self.truth = self._compute_truth(act, _new_tuple(_Stepped, (tracks, thrust, w_eff,
                                                                    waves.fx_n, waves.fy_n,
                                                                    accel)))
        return self.truth

    def _contact_and_immersion(self) -> tuple[Immersion, float, _Hydro]:
        """Put a grounded vehicle on the beach, take the water's buoyancy, lift off when it
        carries the weight; return the immersion, the weight on the tracks, N, and the water
        at the pose."""
        if self.in_contact:
            gz, gpitch, groll, _ = self._ground_pose()
            self.z_cg, self.pitch, self.roll = gz + self._kg, gpitch, groll
        hydro = self._hydro()
        imm = immersion(hydro.areas, self.hull.strip_length_m, self._rho_g,
                        self._afloat_volume, hydro.sums.area_m2)
        if self.in_contact and imm.buoyancy_n >= self._weight:
            self.in_contact = False
        if not (self.in_contact or self.grazing):
            return imm, 0.0, hydro
        return imm, max(traction.effective_weight_n(
            self._weight, imm.volume_m3, self._ground_pose()[3],
            self.vehicle.body.water_density_kgpm3,
            self._g), 0.0), hydro

    def _advance_speed_refs(self, act: Actuation) -> list[float]:
        """Move the track speed loops' references toward the commands; return the targets."""
        land = self.params.land
        full = self.vehicle.drivetrain.full_scale_track_speed_mps
        targets = [act.port_track_pct / 100.0 * full, act.stbd_track_pct / 100.0 * full]
        if targets[0] != 0.0:
            targets[0] -= math.copysign(min(abs(targets[0]), self._port_droop_mps), targets[0])
        alpha = min(self.dt_s / land.speed_loop_time_constant_s, 1.0)
        max_dv = land.speed_loop_accel_mps2 * self.dt_s
        ref = self.ref
        self.ref = [ref[0] + max(-max_dv, min(max_dv, (targets[0] - ref[0]) * alpha)),
                    ref[1] + max(-max_dv, min(max_dv, (targets[1] - ref[1]) * alpha))]
        return targets

    def _track_drives(self, act: Actuation, u_rel: float, w_eff: float,
                      depths: np.ndarray) -> _Drives:
        """The track drives this step: speed loops, friction, paddling, soil contact."""
        p, drive = self.params, self.vehicle.drivetrain
        targets = self._advance_speed_refs(act)
        ref = self.ref
        ground = (self.u - self.r * self._half_sep, self.u + self.r * self._half_sep)
        mean_depth = float(_sum_of(depths)) / depths.size      # depths.mean(), same bits
        track_imm = min(max(mean_depth / self.seakeeping.equilibrium_depth_m, 0.0), 1.0)
        # a loaded loop's speed follows the load: take its reference (no feedback chatter)
        speeds = ref if math.isfinite(self._loop_k) else self.track_speed
        breakaway, paddle_coeff = p.land.breakaway_friction_ratio, \
            p.water.track_paddle_coeff_n_per_mps2
        paddle = [track_paddle_n(paddle_coeff, ref[0], u_rel, track_imm),
                  track_paddle_n(paddle_coeff, ref[1], u_rel, track_imm)]
        others = [drivetrain_friction_n(drive.friction_n + drive.port_extra_friction_n,
                                        speeds[0], ref[0], breakaway) + paddle[0],
                  drivetrain_friction_n(drive.friction_n, speeds[1], ref[1], breakaway)
                  + paddle[1]]
        contact = self._track_contact(w_eff)
        # the speed loops give under load; at a zero command they hold the track (brake);
        # with the belts' inertia over the step (land.inertial_loop)
        belt, inertia = self.track_speed, self._belt_n_per_mps
        port_k, port_ref = inertial_loop(self._loop_k if targets[0] != 0.0 else math.inf,
                                         ref[0], belt[0], inertia)
        stbd_k, stbd_ref = inertial_loop(self._loop_k if targets[1] != 0.0 else math.inf,
                                         ref[1], belt[1], inertia)
        loop_k, loop_ref = (port_k, stbd_k), (port_ref, stbd_ref)
        lin = linearise(contact, loop_ref, ground, tuple(others), loop_k, tuple(belt))
        # motor = L + m/dt (v - v0), v = ref' - L / k': (1 - m/dt / k') L + m/dt (ref' - v0);
        # a held track: L (its belt follows the ramped reference, left out)
        motor_map = (1.0 - inertia / port_k,
                     inertia * (port_ref - belt[0]) if port_k != math.inf else 0.0,
                     1.0 - inertia / stbd_k,
                     inertia * (stbd_ref - belt[1]) if stbd_k != math.inf else 0.0)
        return _new_tuple(_Drives, (ground, others, paddle, loop_k, loop_ref, motor_map,
                                    contact, lin))

    def _track_contact(self, w_eff: float) -> TrackContact | None:
        """The tracks' patches on the sand: dry or wet soil by position; under the surf the
        saturated share of the patches (sand under water) takes the pore suction."""
        if w_eff <= 0.0:
            return None
        if self.x < self.params.world.wet_sand_start_x_m:
            return TrackContact(w_eff / 2.0, self._dry_soil, self._track_area, self._track_len)
        saturation = 0.0
        if self._suction.suction_ratio_per_mps > 0.0:
            saturation = saturated_share(self._water_over_tracks())
        return TrackContact(w_eff / 2.0, self._wet_soil, self._track_area, self._track_len,
                            self._suction, saturation)

    def _thrust_n(self, act: Actuation, eta: np.ndarray) -> list[float]:
        """Port and starboard propeller thrust, N, with their depth under the surface."""
        drive = self.vehicle.drivetrain
        if act is not self._open_water_of:      # per command (frozen)
            self._open_water = (prop_thrust_n(act.port_prop_pct, drive),
                                prop_thrust_n(act.stbd_prop_pct, drive))
            self._open_water_of = act
        port, stbd = self._open_water
        prop_share = self._prop_thrust_factors(eta)
        return [port * prop_share[0], stbd * prop_share[1]]

    def _wave_moments(self, areas: np.ndarray, water, yaw_cs: tuple,
                      sums: StripSums) -> WaveMoments:
        """The strips' wave moments (waves.moments.strip_moments), else none."""
        if not self.params.wave_moments.strip_moments or self.world.calm:
            return self._no_moments
        return wave_moments(self.world.calm, areas, self.hull.strip_length_m, water,
                            self.params.waves, self.vehicle.body.water_density_kgpm3,
                            self.hull.station_x_m, self.hull.station_y_m, yaw_cs,
                            self._wave_lever_z, self._sway_inertia_coeff, sums)

    def _water_yaw_rate(self, areas: np.ndarray, water, yaw_cs: tuple,
                        sums: StripSums) -> float:
        """The water's yaw rate over the hull that the yaw damping acts against (a strip-wise
        wave moment too: waves.moments.strip_moments), else 0, rad/s."""
        if not self.params.wave_moments.strip_moments or self.world.calm:
            return 0.0
        return water_yaw_rate_rps(areas, water, self.hull.station_x_m, self.hull.station_y_m,
                                  yaw_cs, self._surge_to_sway_drag, sums)

    def _water_over_tracks(self) -> np.ndarray:
        """Height of the surface over the sand at the strips along the tracks' contact, m."""
        hydro = self._hydro()
        if self._over_tracks_of is not hydro:      # once per pose: contact, then resistance
            px, water = hydro[:2]
            strips = self._track_strips               # the points' indices, all below n
            self._over_tracks = (water.elevation_m[strips]
                                 - self.world.beach.heights_m(px[strips]))
            self._over_tracks_of = hydro
        return self._over_tracks

    def _track_wetness(self) -> float:
        """Share of the tracks' height under the surface (over the contact length), 0..1."""
        return track_wetness(self._water_over_tracks(), self.vehicle.body.hull_clearance_m)

    def _body_forces(self, drives: _Drives, imm: Immersion, waves: WaveForcing,
                     thrust: list[float], w_eff: float, rel_water: tuple,
                     yaw_cs: tuple, wave_yaw_nm: float = 0.0) -> BodyForces:
        """Every horizontal force in body axes but the tracks' soil forces (those go into the
        implicit solve), summed by effect in one place. A new force is one more term here."""
        land, wat, half = self.params.land, self.params.water, self._half_sep
        c, s = yaw_cs
        terms = [paddle_wrench(drives.paddle, half)]
        if w_eff > 0.0:
            terms += rolling_resistance(w_eff, drives.ground, land, half)
            terms += lateral_resistance(w_eff, self.v, self.r, self._lat_s, land, self._weight)
            gravity = slope_gravity(self._weight, imm.buoyancy_n,
                                    self.world.beach.gradient(self.x), c, s)
            terms += gravity
            if self.params.surf.wet_motion_resistance_coeff > 0.0:
                terms += surf_resistance(w_eff, self._track_wetness(), self._wave_height_m,
                                         drives.ground, self.params.surf, half,
                                         self._other_pull_n(w_eff, gravity))
        terms += propulsion(thrust, wat.prop_walk_ratio, self.params.propeller.x_m, half)
        terms.append(hydrodynamic_drag(*rel_water, imm.fraction, wat))
        ex, ey, en = self._external
        terms.append(odom_force(waves.fx_n + ex, waves.fy_n + ey,
                                en + wave_yaw_nm if wave_yaw_nm else en, c, s))
        return sum_wrenches(terms)

    def _other_pull_n(self, w_eff: float, gravity: list) -> float:
        """What a tow line's load cell adds to the wet sand's resistance while pulling the
        vehicle the way it moves: the rolling resistance and the slope's gravity against the
        motion (surf.max_resistance_n bounds the sum), N."""
        along_n = gravity[0].x_n if gravity else 0.0
        direction = math.tanh(self.u / 0.05) if self.u else 1.0
        return self.params.land.rolling_resistance_coeff * w_eff + max(-along_n * direction, 0.0)

    def _integrate_plane(self, forces: BodyForces, drives: _Drives, frac: float,
                         yaw_cs: tuple) -> TrackState:
        """Planar rigid body with added mass (semi-implicit Euler): new surge, sway, yaw rate,
        track speeds and pose; return the tracks' state."""
        dt, wat, half = self.dt_s, self.params.water, self._half_sep
        u0, v0, r0 = self.u, self.v, self.r
        m_x = self._mass * (1.0 + wat.surge_added_mass_ratio * frac)
        m_y = self._mass * (1.0 + wat.sway_added_mass_ratio * frac)
        i_z = wat.yaw_inertia_kg_m2 + self._yaw_added_inertia * frac
        dv = dt * (forces.y_n - m_x * u0 * r0) / (m_y - dt * forces.dy_dv)
        base = (forces.x_n + m_y * v0 * r0, forces.n_nm, m_x, i_z, forces.dx_du, forces.dn_dr)
        du, dr, new, limited = self._solve_surge_yaw(base, drives)
        self.u, self.v, self.r = u0 + du, v0 + dv, r0 + dr
        ground_new = (self.u - self.r * half, self.u + self.r * half)
        speeds, motor = self._belts(limited, new, ground_new, drives)
        self.track_speed = speeds
        slips = [traction.slip_f(speeds[0], ground_new[0]),
                 traction.slip_f(speeds[1], ground_new[1])]
        c, s = yaw_cs
        self.yaw = (self.yaw + dt * self.r + math.pi) % (2.0 * math.pi) - math.pi
        self.x += dt * (c * self.u - s * self.v)
        self.y += dt * (s * self.u + c * self.v)
        return _new_tuple(TrackState, (speeds, new, motor, slips))

    def _belt_inertial(self, contact) -> bool:
        """Whether a motor at its limit drives a belt with inertia against the soil."""
        return self._belt_n_per_mps > 0.0 and contact is not None

    def _belts(self, limited: list, force_n: list, ground_mps: tuple,
               drives: _Drives) -> tuple[list, list]:
        """Both tracks' belt speeds (m/s) and motor forces (N) after the step."""
        if limited[0] or limited[1]:
            speeds = [self._belt_speed(i, limited[i], force_n[i], ground_mps[i], drives)
                      for i in (0, 1)]
            return speeds, [self._motor_force_n(i, limited[i], force_n[i], drives)
                            for i in (0, 1)]
        others, loop_k, loop_ref, motor_map = (drives.others, drives.loop_k, drives.loop_ref,
                                               drives.motor_map)
        load = (force_n[0] + others[0], force_n[1] + others[1])
        return ([_loaded_speed(loop_ref[0], load[0], loop_k[0]),
                 _loaded_speed(loop_ref[1], load[1], loop_k[1])],
                [motor_map[0] * load[0] + motor_map[1], motor_map[2] * load[1] + motor_map[3]])

    def _belt_speed(self, i: int, limited: int, force_n: float, ground_mps: float,
                    drives: _Drives) -> float:
        """A track's belt speed after the step, m/s: its loop's loaded speed; at the motor's
        limit the belt the motor's force accelerates against the soil's, m_eq (v - v0) / dt =
        +-max - o - F (without inertia, or sliding at the soil's strength: the speed at
        which the soil takes that force)."""
        if limited == _SLIDING or (limited and not self._belt_inertial(drives.contact)):
            return motor_limited_speed(drives.contact, self.ref[i], ground_mps, force_n)
        if limited:
            return self.track_speed[i] + (limited * self._max_motor_n - drives.others[i]
                                          - force_n) / self._belt_n_per_mps
        return _loaded_speed(drives.loop_ref[i], force_n + drives.others[i], drives.loop_k[i])

    def _motor_force_n(self, i: int, limited: int, force_n: float, drives: _Drives) -> float:
        """A track motor's force, N: the soil's, the drivetrain's friction and paddling and
        what accelerates the belt (rotor, belt, wheels), m_eq (v - v0) / dt. A held track
        (it keeps the reference's speed: the ramp's <= 2 m/s^2 left out) and a sliding one
        without it; a motor at its limit with inertia gives exactly its limit."""
        if limited in (1, -1) and self._belt_inertial(drives.contact):
            return limited * self._max_motor_n
        load_n = force_n + drives.others[i]
        if limited:
            return load_n
        return self._loop_motor_n(i, load_n, drives)

    @staticmethod
    def _loop_motor_n(i: int, load_n: float, drives: _Drives) -> float:
        """The motor force of a track's loop giving ``load_n`` to the soil and the drivetrain
        (its belt at the loaded speed, accelerated from the last one), N."""
        gain, offset = drives.motor_map[2 * i:2 * i + 2]
        return gain * load_n + offset

    def _limited_ref(self, i: int, motor_n: float, others_n: float) -> float:
        """A belt driven at the motor's limit as a loop of stiffness m_eq / dt (no other
        force): its reference v0 + (motor - o) dt / m_eq, m/s."""
        return self.track_speed[i] + (motor_n - others_n) / self._belt_n_per_mps

    def _at_motor_limit(self, i: int, motor_n: float, drives: _Drives, g_lin: tuple,
                        g_old: tuple) -> tuple[float, float]:
        """A track whose motor gives its limit ``motor_n``: its soil force linearised in the
        ground speed, (force at g_old, d force / d ground). The belt the motor accelerates
        against the soil is a loop of stiffness m_eq / dt (land.inertial_loop); without
        inertia the soil takes the motor's force less the friction (derivative 0)."""
        if not self._belt_inertial(drives.contact):
            return motor_n - drives.others[i], 0.0
        ref = self._limited_ref(i, motor_n, drives.others[i])
        k = self._belt_n_per_mps
        lin = linearise(drives.contact, (ref, ref), (g_lin[i], g_lin[i]), (0.0, 0.0), (k, k),
                        (self.track_speed[i], self.track_speed[i]))
        slope = lin.dforce_dground[0]
        return lin.force_n[0] + slope * (g_old[i] - g_lin[i]), slope

    def _solve_surge_yaw(self, base: tuple, drives: _Drives):
        """Surge and yaw-rate change, implicit in the soil forces: Newton passes, each
        linearising the soil forces at the previous pass's ground speeds; a track whose motor
        cannot give what the soil would take is held at the motor's limit (its derivative
        drops out). Where that fails the tracks grip. Returns (du, dr, forces, limited)."""
        u0, r0, half = self.u, self.r, self._half_sep
        contact, lin, ground, others = drives.contact, drives.lin, drives.ground, drives.others
        g_lin = ground
        converged = contact is None
        for _ in range(_NEWTON_PASSES):
            du, dr, new, limited = self._solve_tracks(base, lin, g_lin, ground, drives)
            if contact is None or all(limited):
                converged = True
                break
            g_next = (u0 + du - (r0 + dr) * half, u0 + du + (r0 + dr) * half)
            if max(abs(g_next[0] - g_lin[0]), abs(g_next[1] - g_lin[1])) < _NEWTON_TOL_MPS:
                converged = True
                break
            guess = predicted_speeds(lin, drives.loop_k, g_lin, g_next)
            g_lin = g_next
            lin = linearise(contact, drives.loop_ref, g_lin, tuple(others), drives.loop_k,
                            guess)
        if contact is not None:
            slip_p, slip_s = lin.speed_mps[0] - ground[0], lin.speed_mps[1] - ground[1]
            if slip_p * (slip_p - du + dr * half) < 0.0 \
                    or slip_s * (slip_s - du - dr * half) < 0.0:
                converged = False      # a track's slip would change sign within the step
        if converged:
            return du, dr, new, limited
        # the soil force is nearly a step at these slips (firm sand, low speed): the tracks
        # grip; solve the step with the ground under the tracks moving at the tracks'
        # (loaded) speeds, within what the soil and the motors can give
        return self._grip_step(base, drives)

    def _follow_ground(self) -> None:
        """On the ground: take the beach's pose; the rates are the pose's change over the step."""
        dt = self.dt_s
        ngz, npitch, nroll, _ = self._ground_pose()
        nz = ngz + self._kg
        self.heave_vel = (nz - self.z_cg) / dt
        self.roll_rate = (nroll - self.roll) / dt
        self.pitch_rate = (npitch - self.pitch) / dt
        self.z_cg, self.pitch, self.roll = nz, npitch, nroll

    def _touchdown_rates(self) -> None:
        """The rates on touching down. A hull that fell onto the sand from afloat stops (an
        inelastic impact: the IMU's jolt). One that touched the beach at the step's start,
        lying on it or grazing it with a track end, never left it: it keeps the rates of its
        pose's change over the step, as on the ground (``_follow_ground``): a lift-off the
        beach met again, a grazing hull settling onto its tracks. Stopping it read as a 3-7
        m/s^2 jolt in the IMU with no landing, which the estimator took for a dynamic draft
        (issue 18: seed 2026 runs 0, 173, seed 2027 run 86, the wave 8-11 cm low)."""
        z0, pitch0, roll0, grounded = self._step_pose
        if not grounded:
            self.heave_vel = self.roll_rate = self.pitch_rate = 0.0
            return
        dt = self.dt_s
        self.heave_vel = (self.z_cg - z0) / dt
        self.pitch_rate = (self.pitch - pitch0) / dt
        self.roll_rate = (self.roll - roll0) / dt

    def _float_free(self, imm: Immersion, waves: WaveMoments, sums: StripSums) -> None:
        """Afloat: heave, roll and pitch under the strips' buoyancy (and the waves' strip
        moments), with damping scaled by the submerged share, then touch down if a track end
        reaches the sand."""
        dt, sk, frac = self.dt_s, self.seakeeping, imm.fraction
        strip_f = self._rho_g * self.hull.strip_length_m    # the strips' buoyancy per m^2
        m_roll = strip_f * sums.area_y_m3
        m_pitch = -strip_f * sums.area_x_m3
        if waves is not self._no_moments:
            m_roll += waves.roll_nm
            m_pitch += waves.pitch_nm
        self.heave_vel += dt * (imm.buoyancy_n - self._weight - sk.heave_damping_n_per_mps
                                * self.heave_vel * frac) / sk.heave_mass_kg
        self.roll_rate += dt * (m_roll - sk.roll_damping_nm_per_rps
                                * self.roll_rate * frac) / sk.roll_inertia_kg_m2
        self.pitch_rate += dt * (m_pitch - sk.pitch_damping_nm_per_rps
                                 * self.pitch_rate * frac) / sk.pitch_inertia_kg_m2
        self.z_cg += dt * self.heave_vel
        self.roll += dt * self.roll_rate
        self.pitch += dt * self.pitch_rate
        self.grazing = False
        self._touchdown()

    def _solve_tracks(self, base: tuple, lin, g_lin: tuple, g_old: tuple, drives: _Drives):
        """Implicit surge and yaw-rate change with the soil forces linearised at ``g_lin``.

        Returns (du, dr, soil force per track, which tracks the motor limits: +-1 at +-its
        limit, else 0).
        """
        x0, n0, m_x, i_z, j_u, j_r = base
        dt, half = self.dt_s, self._half_sep
        deriv = list(lin.dforce_dground)
        force = [lin.force_n[i] + deriv[i] * (g_old[i] - g_lin[i]) for i in range(2)]
        limited = [0, 0]
        for _ in range(3):
            # [m_x - dt (j_u + Dp + Ds), -dt p (Ds - Dp); -dt p (Ds - Dp), i_z - dt (j_r + p^2
            # (Dp + Ds))] [du, dr] = dt [X + Fp + Fs, N + p (Fs - Fp)]
            cross = -dt * half * (deriv[1] - deriv[0])
            a11 = m_x - dt * (j_u + deriv[0] + deriv[1])
            a22 = i_z - dt * (j_r + (deriv[0] + deriv[1]) * half * half)
            b1 = dt * (x0 + force[0] + force[1])
            b2 = dt * (n0 + (force[1] - force[0]) * half)
            det = a11 * a22 - cross * cross
            du = (b1 * a22 - cross * b2) / det
            dr = (a11 * b2 - cross * b1) / det
            new = [force[0] + deriv[0] * (du - dr * half), force[1] + deriv[1] * (du + dr * half)]
            again = False
            motor_map = drives.motor_map
            for i in range(2):
                need = motor_map[2 * i] * (new[i] + drives.others[i]) + motor_map[2 * i + 1]
                if not limited[i] and abs(need) > self._max_motor_n:
                    limited[i] = 1 if need > 0.0 else -1
                    force[i], deriv[i] = self._at_motor_limit(
                        i, limited[i] * self._max_motor_n, drives, g_lin, g_old)
                    again = True
            if not again:
                break
        return du, dr, new, limited

    def _grip_step(self, base: tuple, drives: _Drives):
        """Surge and yaw-rate change with the tracks gripping (no slip): the ground under
        each track moves at the track's loaded speed g_i = ref_i - c_i (F_i + o_i), c_i =
        1/k_i the loop's compliance (0: a held track runs at its reference). A motor at its
        limit drives its belt against the soil (a loop of compliance dt / m_eq:
        ``_limited_ref``; without inertia its force less the friction reaches the soil); a
        track beyond the soil's strength slides at it, the other still grips. Returns (du,
        dr, forces, limited: +-1 at the motor's limit, _SLIDING)."""
        x0, n0, m_x, i_z, j_u, j_r = base
        dt, half = self.dt_s, self._half_sep
        comp = [0.0 if math.isinf(k) else 1.0 / k for k in drives.loop_k]
        ref, other = list(drives.loop_ref), list(drives.others)
        # du = a (x0 + F0 + F1), half dr = b (n0 / half + F1 - F0): the ground speeds' change
        # per N is a + b of the track's own force, a - b of the other's
        a = dt / (m_x - dt * j_u)
        b = dt * half * half / (i_z - dt * j_r)
        turn = b * n0 / half
        strength = drives.contact.strength_n()
        limited, fixed = [0, 0], [None, None]
        for _ in range(4):
            rhs = [ref[0] - comp[0] * other[0] - drives.ground[0] - a * x0 + turn,
                   ref[1] - comp[1] * other[1] - drives.ground[1] - a * x0 - turn]
            force = _grip_forces(a, b, rhs, comp, fixed)
            again = False
            for i in range(2):
                if limited[i] == _SLIDING:
                    continue
                motor = self._loop_motor_n(i, force[i] + drives.others[i], drives)
                if not limited[i] and abs(motor) > self._max_motor_n:
                    limited[i] = 1 if motor > 0.0 else -1
                    cap = limited[i] * self._max_motor_n
                    if self._belt_inertial(drives.contact):
                        comp[i] = 1.0 / self._belt_n_per_mps
                        ref[i], other[i] = self._limited_ref(i, cap, drives.others[i]), 0.0
                    else:
                        fixed[i] = cap - drives.others[i]
                    again = True
                elif abs(force[i]) > strength:
                    limited[i], fixed[i] = _SLIDING, math.copysign(strength, force[i])
                    again = True
            if not again:
                break
        force = [min(max(f, -strength), strength) for f in force]
        du = a * (x0 + force[0] + force[1])
        dr = b * (n0 / half + force[1] - force[0]) / half
        return du, dr, force, limited

    def _prop_thrust_factors(self, eta: np.ndarray) -> list[float]:
        """Port and starboard thrust shares from each propeller's depth under the surface."""
        prop = self.params.propeller
        hub_z = (self.z_cg + prop.hub_z_m - self._kg - prop.x_m * math.sin(self.pitch))
        n, sr = self._n_stations, math.sin(self.roll)
        port_eta, stbd_eta = eta[n + 4:n + 6].tolist()
        return [propeller_thrust_factor(port_eta - (hub_z + self._half_sep * sr),
                                        prop.diameter_m, prop.ventilation_depth_m),
                propeller_thrust_factor(stbd_eta - (hub_z + -self._half_sep * sr),
                                        prop.diameter_m, prop.ventilation_depth_m)]

    def _touchdown(self) -> None:
        """Land on the sand when a track end reaches it (an inelastic contact).

        Unless the water would carry the whole weight of the vehicle lying there: the sand
        can only push up, so it cannot hold a buoyant hull down. The hull then grazes the
        sand with a track end (``grazing``): it is kept out of it, any downward heave is
        stopped, it goes on pitching and rolling afloat, and the sand carries what the water
        does not (the weight less the buoyancy, on the tracks).
        """
        base = self.z_cg - self._kg
        half = self._track_len / 2.0
        # the beach is monotonic in x: the ground under the tracks (the mean of its heights
        # half a track length fore and aft) is at most the higher of those at x -+ half; the
        # ground's pitch and roll are at most the slope's angle, so the lowest track point
        # (below) is at least base - half min(1, |pitch| + slope) - half_sep min(1, |roll| +
        # slope) (|sin a| <= |a|): clear above it, no contact
        beach = self.world.beach
        reach = half * min(1.0, abs(self.pitch) + beach.slope_rad) \
            + self._half_sep * min(1.0, abs(self.roll) + beach.slope_rad)
        if base - reach > max(beach.height_m(self.x - half),
                              beach.height_m(self.x + half)) + _CLEAR_MARGIN_M:
            return
        gz, gpitch, groll, _ = self._ground_pose()
        lowest = base - traction.track_end_drop_m(
            self._track_len, self.vehicle.body.hull_separation_m, self.pitch - gpitch,
            self.roll - groll)
        if lowest > gz:
            return
        floating = (self.z_cg, self.pitch, self.roll)
        self.z_cg, self.pitch, self.roll = gz + self._kg, gpitch, groll
        if self._grounded_buoyancy() >= self._weight:
            self.z_cg, self.pitch, self.roll = floating
            self.z_cg += gz - lowest
            # the sand lifts the track end clear: the hull rises at the rate it moved over the
            # step (at least its own), as a hull on the beach follows it (the heave once
            # stopped while the sand lifted it: the IMU felt no climb, a jolt at each end)
            self.heave_vel = max(self.heave_vel, (self.z_cg - self._step_pose[0]) / self.dt_s)
            self.grazing = True
            return
        self.in_contact = True
        self._touchdown_rates()

    # ---------------------------------------------------------------------- truth
    def _at_rest(self, volume: float) -> _Stepped:
        """What a step would have left after reset or perturb: no motion, no forces."""
        w_eff = traction.effective_weight_n(
            self._weight, volume, math.atan(abs(self.world.beach.gradient(self.x))),
            self.vehicle.body.water_density_kgpm3, self._g) \
            if self.in_contact or self.grazing else 0.0
        idle = TrackState([0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0])
        return _Stepped(idle, [0.0, 0.0], w_eff, 0.0, 0.0, (0.0, 0.0, 0.0))

    def _electrical(self, tracks: TrackState,
                    thrust: list[float]) -> tuple[list[float], list[float], float]:
        """Track motor currents, propeller currents (A) and the battery voltage (V)."""
        drive = self.vehicle.drivetrain
        speeds, motor = tracks.track_speed_mps, tracks.motor_force_n
        gain = drive.track_force_gain_n_per_a
        no_load, fade = drive.no_load_current_a, drive.friction_fade_mps
        currents = [motor[0] / gain + no_load * math.tanh(speeds[0] / fade),
                    motor[1] / gain + no_load * math.tanh(speeds[1] / fade)]
        max_i, max_thrust = self.params.water.prop_max_current_a, drive.max_prop_thrust_n
        prop_i = [max_i * min(abs(thrust[0]) / max_thrust, 1.0) ** 1.5,
                  max_i * min(abs(thrust[1]) / max_thrust, 1.0) ** 1.5]
        battery = drive.motor_voltage_v - self.params.battery_internal_resistance_ohm * (
            abs(currents[0]) + abs(currents[1]) + prop_i[0] + prop_i[1])
        return currents, prop_i, battery

    def _medium(self, touching: bool, volume: float) -> str:
        if not touching:
            return Medium.WATER
        if volume < _LAND_FRACTION * self._afloat_volume:
            return Medium.LAND
        return Medium.TRANSITION

    def _sensor_depths(self, px: np.ndarray, eta: list, sp: float,
                       cp_cr: float) -> tuple[float, float, float]:
        """Fore and aft water sensors' depth under the surface, and the sounder's reading:
        the depth of the water under it, or (out of the water) minus its height above it.
        ``sp``: sin(pitch), ``cp_cr``: cos(pitch) cos(roll); a sensor at body (x, z) is at
        base_z - x sp + z cp_cr."""
        sens = self.vehicle.sensors
        base_z = self.z_cg - self._kg
        sounder_z = base_z - sens.depth_sounder_x_m * sp + sens.depth_sounder_z_m * cp_cr
        sounder_ground = self.world.beach.height_m(float(px[self._n_stations + 3]))
        if eta[3] > sounder_z:
            sounder = sounder_z - sounder_ground
        else:
            sounder = eta[3] - sounder_z
        return (eta[1] - (base_z - sens.fore_water_x_m * sp + sens.fore_water_z_m * cp_cr),
                eta[2] - (base_z - sens.aft_water_x_m * sp + sens.aft_water_z_m * cp_cr),
                sounder)

    def _compute_truth(self, act: Actuation, stepped: _Stepped | None) -> Truth:
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        px, water, _, _, sums = self._hydro()
        eta = water.elevation_m[self._n_stations:].tolist()   # base_link, fore, aft, sounder
        volume = sums.area_m2 * self.hull.strip_length_m
        beach = self.world.beach
        ground = beach.height_m(self.x)
        sp, cp = math.sin(self.pitch), math.cos(self.pitch)
        sr, cr = math.sin(self.roll), math.cos(self.roll)
        fore, aft, sounder = self._sensor_depths(px, eta, sp, cp * cr)
        st = self._at_rest(volume) if stepped is None else stepped
        accel, tracks, thrust, w_eff = st.accel, st.tracks, st.thrust_n, st.w_eff_n
        g_up = self._g + accel[2]
        currents, prop_i, battery = self._electrical(tracks, thrust)
        # touching now, or during the step just taken (its track forces acted on the sand)
        touching = self.in_contact or self.grazing or w_eff > 0.0
        # positional, in Truth's field order (47 keyword arguments cost ~1.5 us a step more)
        return Truth(
            self.t_s, self.x, self.y, self.z_cg - self._kg,                  # t, x, y, z
            self.roll, self.pitch, self.yaw,
            self.u, self.v, self.heave_vel,                                  # surge, sway, heave
            self.roll_rate, self.pitch_rate, self.r,
            accel[0] - g_up * sp, accel[1] + g_up * sr * cp, g_up * cr * cp,   # accel x, y, z
            act.port_track_pct, act.stbd_track_pct,                          # port/stbd cmd
            tracks.track_speed_mps[0], tracks.track_speed_mps[1],
            tracks.slip[0], tracks.slip[1],
            tracks.soil_force_n[0], tracks.soil_force_n[1],                  # port/stbd force
            currents[0], currents[1],
            act.port_prop_pct, act.stbd_prop_pct,                            # prop cmd
            thrust[0], thrust[1], prop_i[0], prop_i[1],                      # thrust, current
            battery, volume, w_eff,                             # battery, volume, eff. weight
            (max(self._weight - self._rho_g * volume, 0.0) / self._weight   # on the tracks
             if touching else 0.0),
            beach.distance_along_slope_m(self.x),                            # waterline dist.
            math.atan(abs(beach.gradient(self.x))), ground,                  # slope, ground
            eta[0], eta[0] - ground,                                         # wave, water depth
            fore, aft, sounder, self._medium(touching, volume),
            c * st.wave_fx_n + s * st.wave_fy_n, touching)        # wave surge force, contact
