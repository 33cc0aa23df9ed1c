"""The vehicle's physical facts as typed settings, built from the shared parameter block.

Values live in config/dukw.yaml (block ``/**``); see shared docs vehicle.md for sources.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from dukw_common.config import ConfigError, ParamValue, build_settings, section


@dataclass(frozen=True)
class VehicleParams:
    """Principal characteristics (vehicle.md section 1)."""

    length_m: float
    beam_m: float
    draft_m: float
    depth_keel_to_deck_m: float
    waterplane_area_m2: float
    hull_separation_m: float
    displacement_n: float
    kg_m: float
    gm_m: float
    lcg_from_bow_m: float
    track_contact_length_m: float
    track_width_m: float
    hull_clearance_m: float
    hull_radius_m: float
    hull_length_m: float
    gravity_mps2: float
    water_density_kgpm3: float

    @property
    def mass_kg(self) -> float:
        """Mass from the displacement (weight), kg."""
        return self.displacement_n / self.gravity_mps2

    @property
    def bow_x_m(self) -> float:
        """Bow in base_link (origin under the LCG), m."""
        return self.lcg_from_bow_m

    @property
    def stern_x_m(self) -> float:
        """Stern in base_link, m."""
        return self.lcg_from_bow_m - self.length_m

    @property
    def displaced_volume_m3(self) -> float:
        """Volume of water displaced when afloat, Delta / (rho g), m^3."""
        return self.displacement_n / (self.water_density_kgpm3 * self.gravity_mps2)


@dataclass(frozen=True)
class SensorMounts:
    """Where the sensors sit in base_link, m (config ``sensors.*``)."""

    fore_water_x_m: float
    fore_water_z_m: float
    aft_water_x_m: float
    aft_water_z_m: float
    depth_sounder_x_m: float
    depth_sounder_z_m: float
    depth_sounder_min_m: float
    imu_z_m: float
    gps_antenna_z_m: float


@dataclass(frozen=True)
class DrivetrainParams:
    """Tracks, propellers and their limits (vehicle.md sections 2-3)."""

    full_scale_track_speed_mps: float
    track_force_gain_n_per_a: float
    continuous_current_limit_a: float
    motor_voltage_v: float
    no_load_current_a: float
    friction_fade_mps: float         # belt speed over which the no-load current builds up
    friction_n: float                # belt friction per track beyond the no-load current
    port_extra_friction_n: float     # the port track's extra friction (the 4 % port bias)
    sprocket_diameter_m: float
    gear_reduction: float
    max_prop_thrust_n: float
    prop_reverse_thrust_ratio: float
    port_bias_pct: float
    max_differential_ratio: float

    def track_friction_n(self, port: bool) -> float:
        """Drivetrain friction one track's motor overcomes besides the soil, N: the no-load
        current's share plus the belt's friction (the port track's extra included)."""
        return (self.no_load_current_a * self.track_force_gain_n_per_a + self.friction_n
                + (self.port_extra_friction_n if port else 0.0))


@dataclass(frozen=True)
class SoilParams:
    """Modified Wong traction parameters (vehicle.md section 6)."""

    cohesion_pa: float
    friction_angle_rad: float
    shear_modulus_m: float

    def __post_init__(self) -> None:
        if self.cohesion_pa < 0 or self.shear_modulus_m < 0:
            raise ConfigError('soil cohesion_pa and shear_modulus_m must be >= 0')
        if not 0.0 <= self.friction_angle_rad < 1.5:
            raise ConfigError('soil friction_angle_rad must be in [0, 1.5) rad')


@dataclass(frozen=True)
class SaturatedSandParams:
    """Dilatancy hardening of the saturated beach sand the tracks shear (issue 13).

    Sheared faster than the pore water can flow in, saturated sand dilates, its pore
    pressure drops and the effective normal stress on the track patch rises by that
    suction: linear in the slip velocity and in the patch's contact pressure, up to the
    cavitation limit (config ``saturated_sand.*``; dukw_model.traction.pore_suction_pa).
    """

    suction_ratio_per_mps: float     # suction / contact pressure per m/s of slip velocity
    max_pore_suction_pa: float       # cavitation limit

    def __post_init__(self) -> None:
        if not (self.suction_ratio_per_mps >= 0.0 and self.max_pore_suction_pa >= 0.0):
            raise ConfigError('saturated_sand suction_ratio_per_mps and max_pore_suction_pa '
                              'must be >= 0')


@dataclass(frozen=True)
class LimitParams:
    """Operating limits on inclines (vehicle.md section 3)."""

    incline_sustained_rad: float
    incline_brief_rad: float


@dataclass(frozen=True)
class SiteParams:
    """The test site: beach slope and sea floor."""

    beach_slope_rad: float
    sea_floor_depth_m: float


def vehicle_params(params: Mapping[str, ParamValue]) -> VehicleParams:
    """Build VehicleParams from dotted parameters (``vehicle.*``)."""
    return build_settings(VehicleParams, params, 'vehicle')


def sensor_mounts(params: Mapping[str, ParamValue]) -> SensorMounts:
    """Build SensorMounts from dotted parameters (``sensors.*``)."""
    return build_settings(SensorMounts, params, 'sensors')


def drivetrain_params(params: Mapping[str, ParamValue]) -> DrivetrainParams:
    """Build DrivetrainParams from dotted parameters (``drivetrain.*``)."""
    return build_settings(DrivetrainParams, params, 'drivetrain')


def limit_params(params: Mapping[str, ParamValue]) -> LimitParams:
    """Build LimitParams from dotted parameters (``limits.*``)."""
    return build_settings(LimitParams, params, 'limits')


def site_params(params: Mapping[str, ParamValue]) -> SiteParams:
    """Build SiteParams from dotted parameters (``site.*``)."""
    return build_settings(SiteParams, params, 'site')


def saturated_sand_params(params: Mapping[str, ParamValue]) -> SaturatedSandParams:
    """Build SaturatedSandParams from dotted parameters (``saturated_sand.*``)."""
    return build_settings(SaturatedSandParams, params, 'saturated_sand')


def soil_params(params: Mapping[str, ParamValue], preset: str | None = None) -> SoilParams:
    """Build SoilParams: a named preset from ``soil_presets.*``, else the ``soil.*`` values."""
    if preset:
        sub = section(params, f'soil_presets.{preset}')
        if not sub:
            names = params.get('soil_presets.names', [])
            raise ConfigError(f'unknown soil preset {preset!r}; known: {names}')
        return build_settings(SoilParams, params, f'soil_presets.{preset}')
    return build_settings(SoilParams, params, 'soil')


@dataclass(frozen=True)
class Vehicle:
    """Every shared physical fact in one object, for cores and tools."""

    body: VehicleParams
    drivetrain: DrivetrainParams
    soil: SoilParams
    limits: LimitParams
    site: SiteParams
    sensors: SensorMounts
    saturated_sand: SaturatedSandParams

    @classmethod
    def from_params(cls, params: Mapping[str, ParamValue]) -> 'Vehicle':
        """Build from dotted parameters (a node's declared values or dukw_common.config)."""
        return cls(vehicle_params(params), drivetrain_params(params), soil_params(params),
                   limit_params(params), site_params(params), sensor_mounts(params),
                   saturated_sand_params(params))

    @classmethod
    def load(cls, path: str | None = None) -> 'Vehicle':
        """Load from the shared block of a parameter file (default: the stack's)."""
        from dukw_common.config import shared_params
        return cls.from_params(shared_params(path))
