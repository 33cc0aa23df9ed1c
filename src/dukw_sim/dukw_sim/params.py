"""The simulator's own settings (config ``sim_node`` block), beyond the shared Vehicle.

Every value's source is in config/dukw.yaml; nothing here has a default.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

from dukw_common.config import ConfigError, ParamValue, build_settings, require
from dukw_common.vehicle import SoilParams, soil_params

from dukw_sim.world import SecondOrder, WaveModel

MOORING_MODELS = ('spring', 'line')

# Override names accepted for the shared site block (the world's beach lives there).
SITE_ALIASES = {'world.beach_slope_rad': 'site.beach_slope_rad',
                'world.sea_floor_depth_m': 'site.sea_floor_depth_m'}


def _positive(obj, *names: str) -> None:
    for name in names:
        if not getattr(obj, name) > 0.0:
            raise ConfigError(f'{type(obj).__name__}.{name} must be > 0')


@dataclass(frozen=True)
class WorldParams:
    """Beach layout beyond the shared site block."""

    flat_start_x_m: float
    wet_sand_start_x_m: float
    dry_soil_preset: str
    hull_stations: int

    def __post_init__(self) -> None:
        if self.flat_start_x_m >= 0.0:
            raise ConfigError('world.flat_start_x_m must be < 0 (landward of the waterline)')
        if not 2 <= self.hull_stations <= 64:
            raise ConfigError('world.hull_stations must be in [2, 64]')


@dataclass(frozen=True)
class WaveParams:
    """Wave field: a regular wave (height H) or a JONSWAP sea (Hs), travelling shoreward."""

    model: str
    significant_height_m: float
    peak_period_s: float
    jonswap_gamma: float
    components: int
    spreading_rad: float
    mean_direction_rad: float
    spreading_exponent_s: float
    directions: int
    spreading_by_frequency: bool         # s(f) of Mitsuyasu, s_max = spreading_exponent_s
    reference_depth_m: float
    breaking_ratio: float
    surge_inertia_coeff: float
    drift_force_coeff: float
    second_order: str                    # none | kinematics | full (world.SecondOrder)

    def __post_init__(self) -> None:
        if self.model not in WaveModel.ALL:
            raise ConfigError(f'waves.model must be one of {WaveModel.ALL}, got {self.model!r}')
        if self.second_order not in SecondOrder.ALL:
            raise ConfigError(f'waves.second_order must be one of {SecondOrder.ALL}, got '
                              f'{self.second_order!r}')
        if self.significant_height_m < 0.0:
            raise ConfigError('waves.significant_height_m must be >= 0')
        _positive(self, 'peak_period_s', 'jonswap_gamma', 'reference_depth_m', 'breaking_ratio')
        if self.components < 1:
            raise ConfigError('waves.components must be >= 1')
        self._check_spreading()

    def _check_spreading(self) -> None:
        if self.spreading_exponent_s < 0.0 or self.directions < 1:
            raise ConfigError('waves.spreading_exponent_s must be >= 0 and '
                              'waves.directions >= 1')
        if self.spreading_by_frequency and self.spreading_exponent_s == 0.0:
            raise ConfigError('waves.spreading_by_frequency needs the cos-2s spreading '
                              '(waves.spreading_exponent_s > 0: its s_max)')
        if self.spreading_exponent_s == 0.0 and self.directions != 1:
            raise ConfigError('waves.directions > 1 needs the cos-2s spreading '
                              '(waves.spreading_exponent_s > 0)')
        if self.spreading_exponent_s > 0.0 and (self.spreading_rad != 0.0
                                                or self.directions < 2):
            raise ConfigError('the cos-2s spreading (waves.spreading_exponent_s > 0) needs '
                              'waves.spreading_rad = 0 and waves.directions >= 2')


@dataclass(frozen=True)
class LandParams:
    """Track drives and the ground (vehicle.md sections 2, 3, 6)."""

    max_current_a: float
    speed_loop_time_constant_s: float
    speed_loop_accel_mps2: float
    speed_loop_droop_mps_per_kn: float
    motor_rotor_inertia_kg_m2: float
    belt_mass_per_area_kgpm2: float
    track_wheels_inertia_kg_m2: float
    port_speed_deficit_pct: float
    breakaway_friction_ratio: float
    rolling_resistance_coeff: float
    lateral_friction_coeff: float
    lateral_slip_speed_mps: float
    lateral_damping_n_per_mps: float
    min_shear_modulus_m: float

    def __post_init__(self) -> None:
        _positive(self, 'max_current_a', 'speed_loop_time_constant_s', 'speed_loop_accel_mps2',
                  'lateral_slip_speed_mps')
        if self.speed_loop_droop_mps_per_kn < 0.0 or self.lateral_damping_n_per_mps < 0.0:
            raise ConfigError('land.speed_loop_droop_mps_per_kn and '
                              'land.lateral_damping_n_per_mps must be >= 0')
        if min(self.motor_rotor_inertia_kg_m2, self.belt_mass_per_area_kgpm2,
               self.track_wheels_inertia_kg_m2) < 0.0:
            raise ConfigError('land.motor_rotor_inertia_kg_m2, land.belt_mass_per_area_kgpm2 '
                              'and land.track_wheels_inertia_kg_m2 must be >= 0')


@dataclass(frozen=True)
class WaterParams:
    """Propellers, hydrodynamic drag and added mass in the plane."""

    yaw_inertia_kg_m2: float
    surge_added_mass_ratio: float
    sway_added_mass_ratio: float
    surge_linear_drag_n_per_mps: float
    surge_quadratic_drag_n_per_mps2: float
    sway_linear_drag_n_per_mps: float
    sway_quadratic_drag_n_per_mps2: float
    yaw_linear_drag_nm_per_rps: float
    yaw_lift_damping_nm_s_per_m: float
    yaw_quadratic_drag_nm_per_rps2: float
    prop_walk_ratio: float
    prop_max_current_a: float
    track_paddle_coeff_n_per_mps2: float

    def __post_init__(self) -> None:
        _positive(self, 'yaw_inertia_kg_m2', 'surge_quadratic_drag_n_per_mps2')


@dataclass(frozen=True)
class SeakeepingParams:
    """Measured natural frequencies and damping (vehicle.md section 5)."""

    heave_natural_hz: float
    roll_natural_hz: float
    pitch_natural_hz: float
    heave_damping_ratio: float
    roll_damping_ratio: float
    pitch_damping_ratio: float

    def __post_init__(self) -> None:
        _positive(self, 'heave_natural_hz', 'roll_natural_hz', 'pitch_natural_hz')
        for name in ('heave_damping_ratio', 'roll_damping_ratio', 'pitch_damping_ratio'):
            if not 0.0 <= getattr(self, name) < 1.0:
                raise ConfigError(f'seakeeping.{name} must be in [0, 1)')


@dataclass(frozen=True)
class SurfParams:
    """Resistance of the wet, partly liquefied sand under the surf (issue 13)."""

    wet_motion_resistance_coeff: float   # x W_e x the tracks' wetted share x H / reference
    reference_wave_height_m: float       # the sea state the coefficient is for
    max_resistance_n: float              # the tow tests' largest resistance (bound)

    def __post_init__(self) -> None:
        _positive(self, 'max_resistance_n', 'reference_wave_height_m')
        if not self.wet_motion_resistance_coeff >= 0.0:
            raise ConfigError('surf.wet_motion_resistance_coeff must be >= 0')


@dataclass(frozen=True)
class WaveMomentParams:
    """Strip-wise wave moments (issue 13): yaw and roll from the transverse wave force."""

    strip_moments: bool                  # false: only the total wave force (no moments)
    transverse_force_z_m: float          # height of the strips' transverse force above the
                                         # keel (the hulls' centre of buoyancy), m
    sway_inertia_from_added_mass: bool   # the strips' transverse Morison C_m is 1 + the
                                         # sway added-mass ratio (false: the surge C_m)
    water_rotation_by_drag: bool         # the water's rotation the yaw damping acts against
                                         # weights cross-flow by the sway drag, along-hull
                                         # flow by the surge drag (false: equally)


@dataclass(frozen=True)
class MooringParams:
    """The drift test's restraint: a spring and a damper to a fixed anchor ('spring') or a
    line to a holder's hand that only pulls and goes slack ('line'), at attach_x_m."""

    model: str                           # 'spring' | 'line'
    stiffness_n_per_m: float             # 'spring': both ways, in x and y
    damping_n_per_mps: float
    attach_x_m: float                    # where the line is made fast, base_link x, m
    line_stiffness_n_per_m: float        # 'line': the rope and the holder's arm in series
    line_damping_n_per_mps: float        # 'line': the holder's arm yielding
    line_holder_distance_m: float        # 'line': hand to the attachment point at the start,
                                         # along the hull's axis, outward, m
    line_slack_m: float                  # 'line': unstretched length beyond that distance, m

    def __post_init__(self) -> None:
        if self.model not in MOORING_MODELS:
            raise ConfigError(f'mooring.model must be one of {MOORING_MODELS}, '
                              f'got {self.model!r}')
        if min(self.stiffness_n_per_m, self.damping_n_per_mps, self.line_stiffness_n_per_m,
               self.line_damping_n_per_mps, self.line_slack_m) < 0.0:
            raise ConfigError('mooring stiffnesses, dampings and line_slack_m must be >= 0')
        _positive(self, 'line_holder_distance_m')


@dataclass(frozen=True)
class StartParams:
    """Where reset() puts the vehicle (x along the beach, m; yaw 0 faces the sea)."""

    sand_x_m: float
    surf_x_m: float
    afloat_x_m: float
    land_clearance_m: float       # 'flat': this far landward of world.flat_start_x_m
    sea_tread_clearance_m: float  # 'sea': floating, the treads this high over the slope


@dataclass(frozen=True)
class PropellerParams:
    """Where each hull's propeller sits and how big it is (shared ``vehicle.propeller.*``)."""

    x_m: float                   # hub in base_link, m (on each hull's centreline)
    hub_z_m: float               # hub above the keel, m
    diameter_m: float
    ventilation_depth_m: float   # tip depth below which the propeller draws air, m

    def __post_init__(self) -> None:
        _positive(self, 'diameter_m')
        if self.ventilation_depth_m < 0.0:
            raise ConfigError('vehicle.propeller.ventilation_depth_m must be >= 0')


@dataclass(frozen=True)
class SimParams:
    """Everything the simulator core needs beyond the shared Vehicle."""

    dt_s: float
    battery_internal_resistance_ohm: float
    world: WorldParams
    waves: WaveParams
    land: LandParams
    water: WaterParams
    seakeeping: SeakeepingParams
    start: StartParams
    dry_soil: SoilParams | None
    propeller: PropellerParams
    surf: SurfParams
    wave_moments: WaveMomentParams
    mooring: MooringParams

    @classmethod
    def from_params(cls, params: Mapping[str, ParamValue]) -> 'SimParams':
        """Build from dotted parameters (the sim_node block overlaid on the shared one)."""
        world = build_settings(WorldParams, params, 'world')
        dry = soil_params(params, world.dry_soil_preset) if world.dry_soil_preset else None
        dt = require(params, 'physics.dt_s')
        if not 0.0 < dt <= 0.02:
            raise ConfigError('physics.dt_s must be in (0, 0.02] s')
        out = cls(dt, require(params, 'physics.battery_internal_resistance_ohm'), world,
                  build_settings(WaveParams, params, 'waves'),
                  build_settings(LandParams, params, 'land'),
                  build_settings(WaterParams, params, 'water'),
                  build_settings(SeakeepingParams, params, 'seakeeping'),
                  build_settings(StartParams, params, 'start'), dry,
                  build_settings(PropellerParams, params, 'vehicle.propeller'),
                  build_settings(SurfParams, params, 'surf'),
                  build_settings(WaveMomentParams, params, 'waves.moments'),
                  build_settings(MooringParams, params, 'mooring'))
        return out


def apply_overrides(params: Mapping[str, ParamValue],
                    overrides: Mapping[str, ParamValue] | None) -> dict[str, ParamValue]:
    """Return ``params`` with dotted ``overrides`` applied; unknown names raise ConfigError.

    ``world.beach_slope_rad`` / ``world.sea_floor_depth_m`` are accepted for the
    shared ``site.*`` names.
    """
    out = dict(params)
    for name, value in (overrides or {}).items():
        key = SITE_ALIASES.get(name, name)
        if key not in out:
            raise ConfigError(f'unknown simulator parameter {name!r}')
        if isinstance(value, float) and not math.isfinite(value):
            raise ConfigError(f'parameter {name!r} must be finite, got {value!r}')
        out[key] = value
    return out
