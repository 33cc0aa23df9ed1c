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

import functools
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

    @functools.cached_property
    def patch(self) -> traction.TrackPatch:
        """One track's patch for ``traction.track_force_f`` (the float path of forces_n)."""
        return traction.TrackPatch(self.weight_per_track_n, self.soil, self.area_m2,
                                   self.length_m, self.suction, self.saturation)

    def forces_n(self, track_mps: np.ndarray, ground_mps: np.ndarray) -> np.ndarray:
        """Force on the vehicle from tracks at ``track_mps`` over ground speeds, N (+ forward)."""
        return np.asarray(traction.track_force_n(track_mps, ground_mps, self.weight_per_track_n,
                                                 self.soil, self.area_m2, self.length_m,
                                                 self.suction, self.saturation))

    def strength_n(self, slipping: bool = False) -> float:
        """The patch's shear strength, N: without pore suction (no slip velocity), or with
        the most suction the saturated sand can hold (``slipping``: a bound at any slip)."""
        suction_pa = self.saturation * self.suction.max_pore_suction_pa if slipping else 0.0
        return self.patch.strength_n(suction_pa)      # traction.max_traction_n, in floats


@dataclass
class TrackLinear:
    """Both tracks' soil forces at the speed loops' equilibrium, and their derivatives."""

    force_n: list            # port, starboard; + pushes the vehicle forward
    dforce_dground: list     # d force / d ground speed, N s/m (<= 0)
    speed_mps: list = field(default_factory=lambda: [0.0, 0.0])   # the tracks' speeds


def _compliant_speeds(patch: traction.TrackPatch, strength: float, ref: list, ground: list,
                      others: list, stiffness: list, guess: list) -> list:
    """Track speeds where the speed loops' force k (ref - v) equals soil + other forces.

    h(v) = F_soil(v, g) + others - k (ref - v) rises with v; safeguarded Newton inside the
    bracket the soil's strength S gives: v in [ref - (S + o)/k, ref + (S - o)/k]. Both tracks
    step together until both have converged; in floats (numpy on two tracks costs more than
    the physics), the same bits as the vectorised form. Returns the speeds and, when they
    converged, the soil forces there (else None).
    """
    force = traction.track_force_f
    lo = [ref[i] - (strength + others[i]) / stiffness[i] for i in range(2)]
    hi = [ref[i] + (strength - others[i]) / stiffness[i] for i in range(2)]
    v = [min(max(guess[i], lo[i]), hi[i]) for i in range(2)]
    for _ in range(_COMPLIANCE_ITERATIONS):
        f = [force(patch, v[0], ground[0]), force(patch, v[1], ground[1])]
        h = [f[i] + others[i] - stiffness[i] * (ref[i] - v[i]) for i in range(2)]
        if abs(h[0]) < _COMPLIANCE_TOL_N and abs(h[1]) < _COMPLIANCE_TOL_N:
            return v, f
        for i in range(2):
            if h[i] > 0.0:
                hi[i] = v[i]
            else:
                lo[i] = v[i]
            slope = (force(patch, v[i] + _PROBE_MPS, ground[i]) - f[i]) / _PROBE_MPS \
                + stiffness[i]
            step = v[i] - h[i] / slope
            v[i] = step if lo[i] < step < hi[i] else 0.5 * (lo[i] + hi[i])
    return v, None


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
    ref = [float(r) for r in ref_mps]
    ground = [float(g) for g in ground_mps]
    stiff = [float(k) for k in stiffness_n_per_mps]
    soft = [math.isfinite(k) for k in stiff]
    patch = contact.patch
    force = traction.track_force_f
    speed = ref
    f0 = None
    if soft[0] or soft[1]:
        guess = ref if guess_mps is None else [float(g) for g in guess_mps]
        k_soft = [stiff[i] if soft[i] else 1.0 for i in range(2)]
        loaded, f_loaded = _compliant_speeds(patch, contact.strength_n(slipping=True), ref,
                                             ground, [float(o) for o in others_n], k_soft,
                                             guess)
        speed = [loaded[i] if soft[i] else ref[i] for i in range(2)]
        if f_loaded is not None and soft[0] and soft[1]:
            f0 = f_loaded                           # the forces at the converged speeds
    if f0 is None:
        f0 = [force(patch, speed[i], ground[i]) for i in range(2)]
    d_g = [(force(patch, speed[i], ground[i] + _PROBE_MPS) - f0[i]) / _PROBE_MPS
           for i in range(2)]
    d_t = [(force(patch, speed[i] + _PROBE_MPS, ground[i]) - f0[i]) / _PROBE_MPS
           for i in range(2)]
    d_g = [d_g[i] * stiff[i] / (stiff[i] + d_t[i]) if soft[i] else d_g[i] for i in range(2)]
    return TrackLinear(f0, d_g, list(speed))


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
