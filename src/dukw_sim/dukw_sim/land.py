"""Tracks on the ground: closed-loop track drives limited by the motor, and the soil.

Each track's controller holds a commanded track speed (100 % = full scale) through a
speed loop; the motor force it may apply is limited by the controller's current limit
(force = gain x (current - no-load current), vehicle.md section 3). The soil answers
with the modified Wong tractive force of ``dukw_model.traction`` for the track's
slip and its share of the effective weight. When the force the soil would take at the
commanded speed exceeds what the motor can give, the track slows until the two balance
(the stall on 19 deg: "without track slip" on firm sand).

The force on the vehicle (a track running backwards pushes backwards) is the shared
``traction.track_force_n``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from dukw_common.vehicle import SaturatedSandParams, SoilParams
from dukw_model import traction

_GRID = np.linspace(0.0, 1.0, 41)
_PROBE_MPS = 1e-3          # ground-speed step for the force derivative
_COMPLIANCE_ITERATIONS = 60   # safeguarded Newton steps for the loaded track speed (the
                              # soil force is steep near no slip: up to ~40 bisections)
_COMPLIANCE_TOL_N = 0.02


@dataclass(frozen=True)
class TrackContact:
    """Where the tracks meet the soil: patch size, share of the weight, the soil."""

    weight_per_track_n: float
    soil: SoilParams
    area_m2: float           # one track's patch, b l
    length_m: float
    suction: SaturatedSandParams = traction.NO_SUCTION   # saturated sand's dilatancy
    saturation: float = 0.0  # 0 dry sand .. 1 saturated (the tracks' wetted share)

    def forces_n(self, track_mps: np.ndarray, ground_mps: np.ndarray) -> np.ndarray:
        """Force on the vehicle from tracks at ``track_mps`` over ground speeds, N (+ forward)."""
        return np.asarray(traction.track_force_n(track_mps, ground_mps, self.weight_per_track_n,
                                                 self.soil, self.area_m2, self.length_m,
                                                 self.suction, self.saturation))

    def strength_n(self, slipping: bool = False) -> float:
        """The patch's shear strength, N: without pore suction (no slip velocity), or with
        the most suction the saturated sand can hold (``slipping``: a bound at any slip)."""
        suction_pa = self.saturation * self.suction.max_pore_suction_pa if slipping else 0.0
        return float(traction.max_traction_n(self.weight_per_track_n, self.soil, self.area_m2,
                                             suction_pa))


@dataclass
class TrackLinear:
    """Both tracks' soil forces at the speed loops' equilibrium, and their derivatives."""

    force_n: list            # port, starboard; + pushes the vehicle forward
    dforce_dground: list     # d force / d ground speed, N s/m (<= 0)
    speed_mps: list = field(default_factory=lambda: [0.0, 0.0])   # the tracks' speeds


def _compliant_speeds(contact: TrackContact, ref: np.ndarray, ground: np.ndarray,
                      others: np.ndarray, stiffness: np.ndarray,
                      guess: np.ndarray) -> np.ndarray:
    """Track speeds where the speed loops' force k (ref - v) equals soil + other forces.

    h(v) = F_soil(v, g) + others - k (ref - v) rises with v; safeguarded Newton inside the
    bracket the soil's strength S gives: v in [ref - (S + o)/k, ref + (S - o)/k].
    """
    strength = contact.strength_n(slipping=True)
    lo = ref - (strength + others) / stiffness
    hi = ref + (strength - others) / stiffness
    v = np.clip(guess, lo, hi)
    for _ in range(_COMPLIANCE_ITERATIONS):
        f = contact.forces_n(np.concatenate([v, v + _PROBE_MPS]), np.concatenate([ground,
                                                                                 ground]))
        h = f[:2] + others - stiffness * (ref - v)
        if np.all(np.abs(h) < _COMPLIANCE_TOL_N):
            break
        hi = np.where(h > 0.0, v, hi)
        lo = np.where(h > 0.0, lo, v)
        slope = (f[2:] - f[:2]) / _PROBE_MPS + stiffness
        step = v - h / slope
        v = np.where((step > lo) & (step < hi), step, 0.5 * (lo + hi))
    return v


def linearise(contact: TrackContact | None, ref_mps: tuple, ground_mps: tuple,
              others_n: tuple = (0.0, 0.0), stiffness_n_per_mps: tuple = (math.inf, math.inf),
              guess_mps: tuple | None = None) -> TrackLinear:
    """Soil forces of the tracks linearised in the ground speeds.

    With a finite speed-loop stiffness k the track slows under load, v = ref - (F + o)/k
    (a proportional speed controller in series with the soil): the forces are taken at
    that equilibrium and the derivative is the series one, dF/dg = D_g k / (k + D_t).
    An infinite k (per track) holds the track at ref.
    """
    if contact is None:
        return TrackLinear([0.0, 0.0], [0.0, 0.0], list(ref_mps))
    ref = np.asarray(ref_mps, dtype=float)
    ground = np.asarray(ground_mps, dtype=float)
    stiff = np.asarray(stiffness_n_per_mps, dtype=float)
    soft = np.isfinite(stiff)
    speed = ref.copy()
    if soft.any():
        guess = ref if guess_mps is None else np.asarray(guess_mps, dtype=float)
        k_soft = np.where(soft, stiff, 1.0)
        speed = np.where(soft, _compliant_speeds(contact, ref, ground,
                                                 np.asarray(others_n, dtype=float), k_soft,
                                                 guess), ref)
    t = np.array([speed[0], speed[0], speed[0] + _PROBE_MPS,
                  speed[1], speed[1], speed[1] + _PROBE_MPS])
    g = np.array([ground[0], ground[0] + _PROBE_MPS, ground[0],
                  ground[1], ground[1] + _PROBE_MPS, ground[1]])
    f = contact.forces_n(t, g).tolist()
    d_g = [(f[1] - f[0]) / _PROBE_MPS, (f[4] - f[3]) / _PROBE_MPS]
    d_t = [(f[2] - f[0]) / _PROBE_MPS, (f[5] - f[3]) / _PROBE_MPS]
    d_g = [float(d_g[i] * stiff[i] / (stiff[i] + d_t[i])) if soft[i] else d_g[i]
           for i in range(2)]
    return TrackLinear([f[0], f[3]], d_g, speed.tolist())


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
