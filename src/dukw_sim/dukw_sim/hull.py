"""Hull strips: buoyancy, wave forces and the seakeeping constants of the twin-cylinder hull.

Each SWATH hull is a right circular cylinder (vehicle.md section 6) cut into equal
strips; a strip's immersed section is the circular segment under the instantaneous
water surface (``dukw_estimation.buoyancy.segment_area_m2``), so the hull's volume is
``buoyancy.hull_volume_from_depths``. The same strips give the heave force and the
roll and pitch moments, and the Froude-Krylov surge force from the water's particle
acceleration. The rigid-body inertias are chosen from the linearised hydrostatic
stiffness at the calm-water equilibrium so that heave, roll and pitch oscillate at the
measured natural frequencies (vehicle.md section 5).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from dukw_common.vehicle import Vehicle
from dukw_estimation.buoyancy import segment_area_m2

from dukw_sim.params import SeakeepingParams


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
                   dx, body.hull_radius_m, bottom, bottom + body.hull_radius_m, n)

    def areas_m2(self, depth_over_bottom_m: np.ndarray) -> np.ndarray:
        """Immersed section of each strip from the water height over its bottom, m^2."""
        return segment_area_m2(depth_over_bottom_m, self.radius_m)

    def calm_equilibrium_depth_m(self, displaced_volume_m3: float) -> float:
        """Water depth over the hull bottoms when floating level in calm water, m."""
        target = displaced_volume_m3 / (2.0 * self.stations_per_hull * self.strip_length_m)
        full = math.pi * self.radius_m ** 2
        if target >= full:
            raise ValueError('the hulls cannot carry the displacement (hull_radius_m too small)')
        lo, hi = 0.0, 2.0 * self.radius_m
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if float(segment_area_m2(mid, self.radius_m)) < target:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi)


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
        """Inertias from the strip stiffness at the calm equilibrium and the measured frequencies."""
        body = vehicle.body
        rho_g = body.water_density_kgpm3 * body.gravity_mps2
        d0 = hull.calm_equilibrium_depth_m(body.displaced_volume_m3)
        eps = 1e-4
        width = (float(segment_area_m2(d0 + eps, hull.radius_m))
                 - float(segment_area_m2(d0 - eps, hull.radius_m))) / (2.0 * eps)
        strip = rho_g * width * hull.strip_length_m
        k_heave = strip * hull.station_x_m.size
        k_roll = strip * float(np.sum(hull.station_y_m ** 2))
        k_pitch = strip * float(np.sum(hull.station_x_m ** 2))
        out = []
        for k, hz, zeta in ((k_heave, params.heave_natural_hz, params.heave_damping_ratio),
                            (k_roll, params.roll_natural_hz, params.roll_damping_ratio),
                            (k_pitch, params.pitch_natural_hz, params.pitch_damping_ratio)):
            inertia = k / (2.0 * math.pi * hz) ** 2
            out.append((inertia, 2.0 * zeta * math.sqrt(k * inertia)))
        (m3, c3), (i4, c4), (i5, c5) = out
        return cls(m3, i4, i5, c3, c4, c5, k_heave, k_roll, k_pitch, d0)
