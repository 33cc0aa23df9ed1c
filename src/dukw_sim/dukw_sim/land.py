"""Tracks on the ground: closed-loop track drives limited by the motor, and the soil.

Each track's controller holds a commanded track speed (100 % = full scale) through a
first-order speed loop; the motor force it may apply is limited by the controller's
current limit (force = gain x (current - no-load current), vehicle.md section 3). The
soil answers with the modified Wong tractive force of ``dukw_estimation.traction`` for
the track's slip and its share of the effective weight. When the force the soil would
take at the commanded speed exceeds what the motor can give, the track slows until the
two balance (the stall on 19 deg; "without track slip" on firm sand).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from dukw_common.vehicle import SoilParams
from dukw_estimation import traction

_GRID = np.linspace(0.0, 1.0, 41)
_SLIP_EPS_MPS = 1e-3


@dataclass
class TrackResult:
    """What one step of both track drives produced (index 0 port, 1 starboard)."""

    track_speed_mps: list
    soil_force_n: list
    motor_force_n: list
    slip: list
    dforce_dground: list       # d(soil force)/d(ground speed), for the implicit step, N s/m
    saturated: list


def soil_forces(track_mps: np.ndarray, ground_mps: np.ndarray, weight_n: float,
                soil: SoilParams, area_m2: float, length_m: float) -> np.ndarray:
    """Modified Wong force of tracks with speeds ``track_mps`` over ground speeds, N."""
    return traction.tractive_force_n(traction.slip(track_mps, ground_mps), weight_n, soil,
                                     area_m2, length_m)


def track_step(ref_mps: tuple, ground_mps: tuple, other_n: tuple, max_motor_n: float,
               weight_per_track_n: float, soil: SoilParams, area_m2: float,
               length_m: float) -> TrackResult:
    """Both tracks: the speed each achieves, the soil force and the motor force.

    ``ref_mps`` are the speed loops' references, ``ground_mps`` the ground speeds under
    the tracks, ``other_n`` the motor's other loads (drivetrain friction, paddling).
    """
    speeds, forces, motor, derivs, sat = [], [], [], [], []
    loaded = weight_per_track_n > 0.0
    if loaded:
        probe_t = np.array([ref_mps[0], ref_mps[0], ref_mps[1], ref_mps[1]])
        probe_g = np.array([ground_mps[0], ground_mps[0] + _SLIP_EPS_MPS,
                            ground_mps[1], ground_mps[1] + _SLIP_EPS_MPS])
        probe_slip = traction.slip(probe_t, probe_g)
        probe = traction.tractive_force_n(probe_slip, weight_per_track_n, soil, area_m2,
                                          length_m)
    for i in range(2):
        ref = ref_mps[i]
        ground = ground_mps[i]
        soil_n = float(probe[2 * i]) if loaded else 0.0
        deriv = (float(probe[2 * i + 1]) - soil_n) / _SLIP_EPS_MPS if loaded else 0.0
        need = soil_n + other_n[i]
        speed = ref
        saturated = abs(need) > max_motor_n
        if saturated:
            target = math.copysign(max_motor_n, need) - other_n[i]
            grid = ground + (ref - ground) * _GRID
            f = soil_forces(grid, np.full_like(grid, ground), weight_per_track_n, soil,
                            area_m2, length_m)
            beyond = np.nonzero(f >= target)[0] if target >= 0.0 else np.nonzero(f <= target)[0]
            j = int(beyond[0]) if beyond.size else grid.size - 1
            if j == 0:
                speed, soil_n = float(grid[0]), float(f[0])
            else:
                f0, f1 = float(f[j - 1]), float(f[j])
                w = (target - f0) / (f1 - f0) if f1 != f0 else 1.0
                speed = float(grid[j - 1] + w * (grid[j] - grid[j - 1]))
                soil_n = f0 + w * (f1 - f0)
            deriv = 0.0
        speeds.append(speed)
        forces.append(soil_n)
        motor.append(soil_n + other_n[i])
        derivs.append(deriv)
        sat.append(saturated)
    if loaded and not any(sat):
        slips = [float(probe_slip[0]), float(probe_slip[2])]
    else:
        slips = traction.slip(np.array(speeds), np.array(ground_mps)).tolist()
    return TrackResult(speeds, forces, motor, slips, derivs, sat)
