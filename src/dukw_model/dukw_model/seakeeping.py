"""Heave, roll and pitch constants afloat from the vehicle's facts (vehicle.md sections 1, 5).

The measured natural frequencies and damping ratios (the shared ``seakeeping.*`` config)
and the hull's waterplane stiffness give each mode's inertia (with added mass) and linear
damping: inertia = k / (2 pi f)^2, damping = 2 zeta sqrt(k inertia). The simulator's hull
(``dukw_sim.hull.Seakeeping``) and the estimator's afloat volume from the heave
acceleration both take the heave mass and damping from ``heave_constants``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from dukw_common.vehicle import VehicleParams
from dukw_model.buoyancy import HullSection

#: heave amplitude the linearised (secant) stiffness of the hull section is taken over, m
HEAVE_SECANT_M = 0.02


@dataclass(frozen=True)
class HeaveConstants:
    """The floating vehicle's heave oscillator."""

    stiffness_n_per_m: float
    mass_kg: float                 # with added mass
    damping_n_per_mps: float


def oscillator_constants(stiffness: float, natural_hz: float,
                         damping_ratio: float) -> tuple[float, float]:
    """(inertia, linear damping) of a mode of ``stiffness`` that oscillates at ``natural_hz``
    with ``damping_ratio``; units follow the stiffness (N/m -> kg, N s/m)."""
    if stiffness <= 0.0 or natural_hz <= 0.0 or damping_ratio < 0.0:
        raise ValueError('oscillator_constants needs positive stiffness and frequency and a '
                         'non-negative damping ratio')
    inertia = stiffness / (2.0 * math.pi * natural_hz) ** 2
    return inertia, 2.0 * damping_ratio * math.sqrt(stiffness * inertia)


def heave_waterplane_m2(section: HullSection, hull_length_m: float) -> float:
    """Both hulls' waterplane for small heaves about the float line, m^2."""
    return 2.0 * section.heave_width_m(HEAVE_SECANT_M) * hull_length_m


def heave_constants(body: VehicleParams, natural_hz: float,
                    damping_ratio: float) -> HeaveConstants:
    """Heave stiffness, mass and damping of the floating vehicle from its facts."""
    waterplane_m2 = heave_waterplane_m2(HullSection.of_body(body), body.hull_length_m)
    stiffness = body.water_density_kgpm3 * body.gravity_mps2 * waterplane_m2
    mass_kg, damping = oscillator_constants(stiffness, natural_hz, damping_ratio)
    return HeaveConstants(stiffness, mass_kg, damping)
