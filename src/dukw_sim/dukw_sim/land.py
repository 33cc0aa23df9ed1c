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

The belt has inertia (the motor's rotor through the reduction, the belt, its wheels):
m_eq dv/dt = k (ref - v) - F_soil - others. Over one step, implicitly (backward Euler),
that is a speed loop of stiffness k + m_eq/dt about the reference (k ref + m_eq/dt v0) /
(k + m_eq/dt), v0 the belt's speed a step ago (``inertial_loop``): the soil solve below
takes it as it takes the controller's loop, and a loaded belt relaxes with the time
constant m_eq / k instead of jumping to its loaded speed.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from dukw_common.vehicle import SaturatedSandParams, SoilParams
from dukw_model import traction

_GRID = np.linspace(0.0, 1.0, 41)
_COMPLIANCE_ITERATIONS = 60   # safeguarded Newton steps for the loaded track speed (the
                              # soil force is steep near no slip: up to ~40 bisections)
_COMPLIANCE_TOL_N = 0.02


def belt_equivalent_mass_kg(rotor_inertia_kg_m2: float, gear_reduction: float,
                            sprocket_diameter_m: float, belt_mass_kg: float,
                            wheels_inertia_kg_m2: float) -> float:
    """One track drive's inertia reflected to the belt, kg: J_rotor (N / r)^2 + m_belt +
    J_wheels / r^2, r the drive sprocket's radius (the wheels' inertia about their axles,
    taken at that radius)."""
    values = (rotor_inertia_kg_m2, gear_reduction, sprocket_diameter_m, belt_mass_kg,
              wheels_inertia_kg_m2)
    if not all(math.isfinite(v) for v in values) or min(values) < 0.0 \
            or gear_reduction <= 0.0 or sprocket_diameter_m <= 0.0:
        raise ValueError(f'belt inertia needs finite values >= 0 (reduction and sprocket '
                         f'diameter > 0), got {values}')
    radius_m = sprocket_diameter_m / 2.0
    return (rotor_inertia_kg_m2 * (gear_reduction / radius_m) ** 2 + belt_mass_kg
            + wheels_inertia_kg_m2 / radius_m ** 2)


def belt_mass_kg(mass_per_area_kgpm2: float, width_m: float, contact_length_m: float,
                 sprocket_diameter_m: float) -> float:
    """A track belt's mass, kg: its areal mass x width x length, the length that of a belt
    around two sprockets of the drive's diameter at the ends of the contact, 2 l + pi d."""
    return mass_per_area_kgpm2 * width_m * (2.0 * contact_length_m
                                            + math.pi * sprocket_diameter_m)


def inertial_loop(stiffness_n_per_mps: float, ref_mps: float, belt_mps: float,
                  inertia_n_per_mps: float) -> tuple[float, float]:
    """A speed loop and its belt's inertia over one implicit step, as one loop.

    m (v - v0) / dt = k (ref - v) - F  <=>  F = (k + m/dt) (ref' - v) with ref' = (k ref +
    m/dt v0) / (k + m/dt). ``inertia_n_per_mps`` = m/dt. Returns (k + m/dt, ref'); a loop
    that holds its speed (k infinite) stays one: (inf, ref).
    """
    if math.isinf(stiffness_n_per_mps) or inertia_n_per_mps == 0.0:
        return stiffness_n_per_mps, ref_mps
    k = stiffness_n_per_mps + inertia_n_per_mps
    return k, (stiffness_n_per_mps * ref_mps + inertia_n_per_mps * belt_mps) / k


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
                      others: list, stiffness: list, guess: list) -> tuple:
    """Track speeds where the speed loops' force k (ref - v) equals soil + other forces.

    h(v) = F_soil(v, g) + others - k (ref - v) rises with v; safeguarded Newton inside the
    bracket the soil's strength S gives: v in [ref - (S + o)/k, ref + (S - o)/k], with the
    soil's analytic slope (``traction.track_force_slopes_f``: one evaluation a pass, no
    probe). Both tracks step together until both have converged; in floats, the two tracks
    written out (numpy on two tracks, or lists of two, cost more than the physics). Returns
    the speeds and, when they converged, the soil forces there and their derivatives in the
    track and the ground speed (else None, None, None).
    """
    slopes = traction.track_force_slopes_f
    r0, r1 = ref
    g0, g1 = ground
    o0, o1 = others
    k0, k1 = stiffness
    lo0, lo1 = r0 - (strength + o0) / k0, r1 - (strength + o1) / k1
    hi0, hi1 = r0 + (strength - o0) / k0, r1 + (strength - o1) / k1
    v0, v1 = min(max(guess[0], lo0), hi0), min(max(guess[1], lo1), hi1)
    for _ in range(_COMPLIANCE_ITERATIONS):
        f0, dv0, dg0 = slopes(patch, v0, g0)
        f1, dv1, dg1 = slopes(patch, v1, g1)
        h0, h1 = f0 + o0 - k0 * (r0 - v0), f1 + o1 - k1 * (r1 - v1)
        if abs(h0) < _COMPLIANCE_TOL_N and abs(h1) < _COMPLIANCE_TOL_N:
            return [v0, v1], [f0, f1], [dv0, dv1], [dg0, dg1]
        v0, lo0, hi0 = _newton_in_bracket(v0, h0, dv0 + k0, lo0, hi0)
        v1, lo1, hi1 = _newton_in_bracket(v1, h1, dv1 + k1, lo1, hi1)
    return [v0, v1], None, None, None


def _newton_in_bracket(v: float, residual: float, slope: float, lo: float,
                       hi: float) -> tuple[float, float, float]:
    """One track's next compliant speed: the bracket narrowed by the residual's sign, then a
    Newton step (``slope``: the soil's derivative plus the loop's stiffness), or the
    bisection when the step leaves the bracket. Returns (speed, lo, hi)."""
    if residual > 0.0:
        hi = v
    else:
        lo = v
    step = v - residual / slope if slope > 0.0 else lo
    return (step if lo < step < hi else 0.5 * (lo + hi)), lo, hi


def _series_slope(d_t: float, d_g: float, stiffness: float, soft: bool) -> float:
    """d force / d ground speed of one track from the soil's derivatives in the track speed
    ``d_t`` and the ground speed ``d_g``: the soil's, or with a soft loop the series one
    D_g k / (k + D_t)."""
    return d_g * stiffness / (stiffness + d_t) if soft else d_g


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
    ref = [float(ref_mps[0]), float(ref_mps[1])]
    ground = [float(ground_mps[0]), float(ground_mps[1])]
    stiff = [float(stiffness_n_per_mps[0]), float(stiffness_n_per_mps[1])]
    soft = [math.isfinite(stiff[0]), math.isfinite(stiff[1])]
    patch = contact.patch
    slopes = traction.track_force_slopes_f
    speed = ref
    f0 = d_t = d_g = None
    if soft[0] or soft[1]:
        guess = ref if guess_mps is None else [float(guess_mps[0]), float(guess_mps[1])]
        k_soft = [stiff[0] if soft[0] else 1.0, stiff[1] if soft[1] else 1.0]
        loaded, f_loaded, dt_loaded, dg_loaded = _compliant_speeds(
            patch, contact.strength_n(slipping=True), ref, ground,
            [float(others_n[0]), float(others_n[1])], k_soft, guess)
        speed = [loaded[0] if soft[0] else ref[0], loaded[1] if soft[1] else ref[1]]
        if f_loaded is not None and soft[0] and soft[1]:
            f0, d_t, d_g = f_loaded, dt_loaded, dg_loaded   # at the converged speeds
    if f0 is None:
        port, stbd = slopes(patch, speed[0], ground[0]), slopes(patch, speed[1], ground[1])
        f0, d_t, d_g = [port[0], stbd[0]], [port[1], stbd[1]], [port[2], stbd[2]]
    return TrackLinear(f0, [_series_slope(d_t[0], d_g[0], stiff[0], soft[0]),
                            _series_slope(d_t[1], d_g[1], stiff[1], soft[1])], list(speed))


def predicted_speeds(lin: TrackLinear, stiffness_n_per_mps: tuple, ground_from_mps: tuple,
                     ground_to_mps: tuple) -> tuple:
    """The loaded tracks' speeds at the ground speeds ``ground_to_mps``, to first order from
    ``lin`` (linearised at ``ground_from_mps``): along a soft loop's equilibrium
    dv/dg = -(series dF/dg) / k = -D_g / (k + D_t); a stiff loop's track keeps its speed.
    The Newton start of the next linearisation."""
    out = []
    for i in (0, 1):
        k, speed = stiffness_n_per_mps[i], lin.speed_mps[i]
        if math.isfinite(k):
            speed -= lin.dforce_dground[i] / k * (ground_to_mps[i] - ground_from_mps[i])
        out.append(speed)
    return tuple(out)


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
