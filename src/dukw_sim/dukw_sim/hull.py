"""Hull strips: buoyancy, wave forces and the seakeeping constants of the twin-cylinder hull.

Each SWATH hull is a right circular cylinder (vehicle.md section 6) cut into equal
strips; a strip's immersed section is ``dukw_model.buoyancy.HullSection`` under the
instantaneous water surface (the estimator's section too): the circular segment up to
the float line, so the hull's volume is ``buoyancy.hull_volume_from_depths`` there. The
cylinders alone are almost wholly immersed when afloat (0.288 of 0.313 m^3): 4 cm above
the float line their waterplane vanishes and a 28 cm wave would leave heave and pitch
without stiffness. Above the float line each hull therefore continues wall-sided (the SWATH
struts), with the waterplane area of vehicle.md section 1 (A_W = 0.89 m^2). The
same strips give the heave force and the roll and pitch moments, and the Froude-Krylov
surge force from the water's particle acceleration. The rigid-body inertias (with added
mass) are chosen from the hydrostatic stiffness at the float line so that heave, roll
and pitch oscillate at the measured natural frequencies (vehicle.md section 5); the
roll stiffness of two hulls 0.81 m apart implies GM ~0.5 m, not the paper's 0.14 m,
so the roll inertia absorbs the difference.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dukw_common.vehicle import Vehicle
from dukw_model.buoyancy import HullSection
from dukw_model.seakeeping import HEAVE_SECANT_M, heave_constants, oscillator_constants

from dukw_sim.params import SeakeepingParams
from dukw_model.fast_numpy import max_of as _max_of


@dataclass(frozen=True)
class HullGeometry:
    """Strip stations of both hulls in base_link (port hull first), and their size."""

    station_x_m: np.ndarray      # (2N,) body x of each strip's middle
    station_y_m: np.ndarray      # (2N,) +p port, -p starboard
    strip_length_m: float
    radius_m: float
    bottom_above_cg_m: float     # hull bottom height relative to the centre of gravity (< 0)
    axis_above_cg_m: float
    stations_per_hull: int
    section: HullSection         # each hull's cross-section (shared with the estimator)

    def __post_init__(self) -> None:
        object.__setattr__(self, '_dry', np.zeros(self.station_x_m.size))

    @classmethod
    def from_vehicle(cls, vehicle: Vehicle, stations_per_hull: int) -> 'HullGeometry':
        """Hulls of waterline length centred on base_link (LCB = LCG in equilibrium)."""
        body = vehicle.body
        n = stations_per_hull
        dx = body.hull_length_m / n
        xs = -body.hull_length_m / 2.0 + dx * (np.arange(n) + 0.5)
        p = body.hull_separation_m / 2.0
        bottom = body.hull_clearance_m - body.kg_m
        return cls(np.concatenate([xs, xs]), np.concatenate([np.full(n, p), np.full(n, -p)]),
                   dx, body.hull_radius_m, bottom, bottom + body.hull_radius_m, n,
                   HullSection.of_body(body))

    @property
    def float_depth_m(self) -> float:
        """Water over the hull bottom when afloat in calm water, m."""
        return self.section.float_depth_m

    @property
    def strut_width_m(self) -> float:
        """Wall-sided width of each hull above the float line, m."""
        return self.section.strut_width_m

    def areas_m2(self, depth_over_bottom_m: np.ndarray) -> np.ndarray:
        """Immersed section of each strip from the water height over its bottom, m^2.

        The cylinder's circular segment up to the float line, wall-sided above it up to the
        deck (``buoyancy.HullSection``, the estimator's section too).
        """
        d = depth_over_bottom_m
        deepest = float(_max_of(d))   # d.max(), same bits
        if deepest <= 0.0:
            return self._dry
        return self.section.area_array_m2(d, deepest)


@dataclass(frozen=True)
class Seakeeping:
    """Heave mass, roll and pitch inertias (with added mass) and linear damping."""

    heave_mass_kg: float
    roll_inertia_kg_m2: float
    pitch_inertia_kg_m2: float
    heave_damping_n_per_mps: float
    roll_damping_nm_per_rps: float
    pitch_damping_nm_per_rps: float
    heave_stiffness_n_per_m: float
    roll_stiffness_nm_per_rad: float
    pitch_stiffness_nm_per_rad: float
    equilibrium_depth_m: float

    @classmethod
    def calibrate(cls, hull: HullGeometry, vehicle: Vehicle,
                  params: SeakeepingParams) -> 'Seakeeping':
        """Inertias from the strip stiffness at the float line and the measured frequencies."""
        body = vehicle.body
        heave = heave_constants(body, params.heave_natural_hz, params.heave_damping_ratio)
        # roll and pitch: the heave waterplane's strips times their lever arm squared
        strip = body.water_density_kgpm3 * body.gravity_mps2 * hull.section.heave_width_m(
            HEAVE_SECANT_M) * hull.strip_length_m
        k_roll = strip * float(np.sum(hull.station_y_m ** 2))
        k_pitch = strip * float(np.sum(hull.station_x_m ** 2))
        out = [(heave.mass_kg, heave.damping_n_per_mps),
               oscillator_constants(k_roll, params.roll_natural_hz, params.roll_damping_ratio),
               oscillator_constants(k_pitch, params.pitch_natural_hz, params.pitch_damping_ratio)]
        (m3, c3), (i4, c4), (i5, c5) = out
        return cls(m3, i4, i5, c3, c4, c5, heave.stiffness_n_per_m, k_roll, k_pitch,
                   hull.float_depth_m)
