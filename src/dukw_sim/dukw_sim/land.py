"""Tracks on the ground: closed-loop track drives limited by the motor, and the soil.

Each track's controller holds a commanded track speed (100 % = full scale) through a
speed loop; the motor force it may apply is limited by the controller's current limit
(force = gain x (current - no-load current), vehicle.md section 3). The soil answers
with the modified Wong tractive force of ``dukw_estimation.traction`` for the track's
slip and its share of the effective weight. When the force the soil would take at the
commanded speed exceeds what the motor can give, the track slows until the two balance
(the stall on 19 deg: "without track slip" on firm sand).

The force on the vehicle (a track running backwards pushes backwards) is the shared
``traction.track_force_n``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dukw_common.vehicle import SoilParams
from dukw_estimation import traction

_GRID = np.linspace(0.0, 1.0, 41)
_PROBE_MPS = 1e-3          # ground-speed step for the force derivative


@dataclass(frozen=True)
class TrackContact:
    """Where the tracks meet the soil: patch size, share of the weight, the soil."""

    weight_per_track_n: float
    soil: SoilParams
    area_m2: float           # one track's patch, b l
    length_m: float

    def forces_n(self, track_mps: np.ndarray, ground_mps: np.ndarray) -> np.ndarray:
        """Force on the vehicle from tracks at ``track_mps`` over ground speeds, N (+ forward)."""
        return np.asarray(traction.track_force_n(track_mps, ground_mps, self.weight_per_track_n,
                                                 self.soil, self.area_m2, self.length_m))


@dataclass
class TrackLinear:
    """Both tracks' soil forces at the speed loops' references, and their derivatives."""

    force_n: list            # port, starboard; + pushes the vehicle forward
    dforce_dground: list     # d force / d ground speed, N s/m (<= 0)


def linearise(contact: TrackContact | None, ref_mps: tuple, ground_mps: tuple) -> TrackLinear:
    """Soil forces of tracks running at the references, linearised in the ground speeds."""
    if contact is None:
        return TrackLinear([0.0, 0.0], [0.0, 0.0])
    t = np.array([ref_mps[0], ref_mps[0], ref_mps[1], ref_mps[1]])
    g = np.array([ground_mps[0], ground_mps[0] + _PROBE_MPS,
                  ground_mps[1], ground_mps[1] + _PROBE_MPS])
    f = contact.forces_n(t, g).tolist()
    return TrackLinear([f[0], f[2]], [(f[1] - f[0]) / _PROBE_MPS, (f[3] - f[2]) / _PROBE_MPS])


def motor_limited_speed(contact: TrackContact | None, ref_mps: float, ground_mps: float,
                        soil_force_n: float) -> float:
    """Track speed between the ground speed and the reference where the soil takes
    ``soil_force_n`` (the force the saturated motor can give), m/s."""
    if contact is None:
        return ref_mps
    grid = ground_mps + (ref_mps - ground_mps) * _GRID
    f = contact.forces_n(grid, np.full_like(grid, ground_mps))
    if ref_mps < ground_mps:
        f, soil_force_n = -f, -soil_force_n
    beyond = np.nonzero(f >= soil_force_n)[0]
    j = int(beyond[0]) if beyond.size else grid.size - 1
    if j == 0:
        return float(grid[0])
    f0, f1 = float(f[j - 1]), float(f[j])
    w = (soil_force_n - f0) / (f1 - f0) if f1 != f0 else 1.0
    return float(grid[j - 1] + min(max(w, 0.0), 1.0) * (grid[j] - grid[j - 1]))
