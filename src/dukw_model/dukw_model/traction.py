"""Track traction: slip and the modified Wong tractive force (vehicle.md section 6).

One implementation for the simulator, the EKF and the terrain fit. Vectorised:
every function takes floats or numpy arrays.

    i   = (v_t - v_r) / v_t                       (signed slip)
    H   = sgn(i) (A c + W_e tan phi) [1 - k/(|i| l) (1 - exp(-|i| l / k))]
    W_e = (Delta - rho g V) cos(theta)

In saturated sand (under the surf) shearing fast dilates the sand faster than the pore water
can flow in: the pore pressure drops and the effective normal stress on the shear surface
rises by that suction (dilatancy hardening). ``SaturatedSandParams`` (config
``saturated_sand.*``) adds it to the strength,
A c + (W_e + A s) tan phi, with s growing with the slip velocity |v_t - v_r| up to the
cavitation limit (``pore_suction_pa``); on dry sand and with no slip it is zero.
"""
from __future__ import annotations

import math

import numpy as np

from dukw_model.scalars import is_scalar

from dukw_common.vehicle import SaturatedSandParams, SoilParams

ArrayLike = float | np.ndarray
_expm1 = np.expm1          # numpy's (not libm's): the array paths' bits
MIN_TRACK_SPEED_MPS = 0.05    # slip's held denominator (slip's default)


#: No dilatancy hardening: the plain (dry-sand) Wong force. The saturated sand's (van Os 1977;
#: Miedema, The Delft Sand, Clay and Rock Cutting Model, 2014: dilatancy-limited cutting forces
#: of saturated sand proportional to the velocity, up to cavitation at rho_w g (10 m + depth))
#: is the shared config's ``saturated_sand.*`` (Vehicle.saturated_sand).
NO_SUCTION = SaturatedSandParams(0.0, 0.0)


def pore_suction_pa(slip_speed_mps: ArrayLike, pressure_pa: ArrayLike, saturation: float,
                    suction: SaturatedSandParams) -> ArrayLike:
    """Pore under-pressure s = saturation x min(ratio |v_slip| p, cavitation limit), Pa (>= 0):
    growing with the slip velocity and with the patch's contact pressure p (the dilating
    layer is the one the grousers pressed into the sand shear)."""
    sat = min(max(float(saturation), 0.0), 1.0)
    ratio, limit = suction.suction_ratio_per_mps, suction.max_pore_suction_pa
    if is_scalar(slip_speed_mps) and is_scalar(pressure_pa):
        return sat * min(ratio * abs(float(slip_speed_mps)) * float(pressure_pa), limit)
    out = sat * np.minimum(ratio * np.abs(np.asarray(slip_speed_mps, dtype=float))
                           * np.asarray(pressure_pa, dtype=float), limit)
    return float(out) if out.ndim == 0 else out


def slip(track_speed_mps: ArrayLike, ground_speed_mps: ArrayLike,
         min_track_speed_mps: float = MIN_TRACK_SPEED_MPS) -> ArrayLike:
    """Signed slip i = (v_t - v_r) / v_t, held sane when the track is nearly stopped.

    Below ``min_track_speed_mps`` the denominator is held at that magnitude (with
    the track's sign), so a stopped track with a moving vehicle gives a large
    negative slip instead of infinity; the result is clipped to [-1, 1].
    """
    if is_scalar(track_speed_mps) and is_scalar(ground_speed_mps):   # scalar path
        return slip_f(float(track_speed_mps), float(ground_speed_mps), min_track_speed_mps)
    v_t = np.asarray(track_speed_mps, dtype=float)
    v_r = np.asarray(ground_speed_mps, dtype=float)
    sign = np.where(v_t >= 0.0, 1.0, -1.0)
    denom = sign * np.maximum(np.abs(v_t), min_track_speed_mps)
    i = np.clip((v_t - v_r) / denom, -1.0, 1.0)
    return float(i) if i.ndim == 0 else i


def saturated_share(depth_at_centre_m: float, depth_per_m: float, length_m: float) -> float:
    """Share of a track patch of ``length_m`` with water over the sand, 0..1, where the water
    depth over the sand is ``depth_at_centre_m`` at the patch's centre and changes by
    ``depth_per_m`` along it (a plane surface over a plane beach): there the sand under the
    track is saturated."""
    half = 0.5 * length_m
    if abs(depth_per_m) * half < 1e-9:
        return 1.0 if depth_at_centre_m > 0.0 else 0.0
    zero_m = -depth_at_centre_m / depth_per_m          # where the depth crosses zero
    wet_m = half - zero_m if depth_per_m > 0.0 else zero_m + half
    return min(max(wet_m / length_m, 0.0), 1.0)


def shear_development(slip_abs: ArrayLike, contact_length_m: float,
                      shear_modulus_m: float) -> ArrayLike:
    """The bracket [1 - k/(|i| l) (1 - exp(-|i| l / k))], 0 at no slip, -> 1 at large slip.

    Safe at |i| -> 0 (series 1 - (1 - x/2) = x/2) and at k -> 0 (-> 1).
    """
    if is_scalar(slip_abs):                                          # scalar path
        return _shear_development_f(abs(float(slip_abs)), contact_length_m, shear_modulus_m)
    s = np.abs(np.asarray(slip_abs, dtype=float))
    if shear_modulus_m <= 1e-9:  # k -> 0: shear fully developed at any slip
        out = np.where(s > 0.0, 1.0, 0.0)
        return float(out) if out.ndim == 0 else out
    x = s * contact_length_m / shear_modulus_m
    small = x < 1e-6
    x_safe = np.where(small, 1.0, x)
    out = np.where(small, x / 2.0, 1.0 + np.expm1(-x_safe) / x_safe)
    return float(out) if out.ndim == 0 else out


def max_traction_n(effective_weight_n: ArrayLike, soil: SoilParams,
                   contact_area_m2: float, suction_pa: ArrayLike = 0.0) -> ArrayLike:
    """Fully developed shear strength of the contact patch: A c + (W_e + A s) tan(phi), N
    (s: the pore suction, ``pore_suction_pa``)."""
    w = np.maximum(np.asarray(effective_weight_n, dtype=float), 0.0)
    if np.any(np.asarray(suction_pa) != 0.0):
        w = w + contact_area_m2 * np.asarray(suction_pa, dtype=float)
    out = contact_area_m2 * soil.cohesion_pa + w * np.tan(soil.friction_angle_rad)
    return float(out) if np.ndim(out) == 0 else out


def tractive_force_n(slip_: ArrayLike, effective_weight_n: ArrayLike, soil: SoilParams,
                     contact_area_m2: float, contact_length_m: float,
                     suction_pa: ArrayLike = 0.0) -> ArrayLike:
    """Modified Wong tractive force H, N, signed like the slip.

    ``contact_area_m2`` and ``effective_weight_n`` are for the tracks the force is
    wanted for: A = 2 b l and the whole W_e for the vehicle, or b l and W_e / 2
    for one track. No weight on the tracks (afloat) gives no cohesion either:
    the patch is off the ground. ``suction_pa`` (pore suction of saturated sand,
    ``pore_suction_pa``) adds A s to the normal force while the patch is on the ground.
    """
    if is_scalar(slip_) and is_scalar(effective_weight_n) and is_scalar(suction_pa):
        i, w = float(slip_), max(float(effective_weight_n), 0.0)
        sign = math.copysign(1.0, i) if i != 0.0 else 0.0      # as np.sign: +0 at either zero
        tan_phi = float(np.tan(soil.friction_angle_rad))       # numpy: the same bits
        normal = w + contact_area_m2 * float(suction_pa) if suction_pa else w
        strength = contact_area_m2 * soil.cohesion_pa + normal * tan_phi if w > 0.0 else 0.0
        return sign * strength * shear_development(i, contact_length_m, soil.shear_modulus_m)
    i = np.asarray(slip_, dtype=float)
    w = np.maximum(np.asarray(effective_weight_n, dtype=float), 0.0)
    strength = np.where(w > 0.0, max_traction_n(w, soil, contact_area_m2, suction_pa), 0.0)
    out = np.sign(i) * strength * shear_development(i, contact_length_m, soil.shear_modulus_m)
    return float(out) if out.ndim == 0 else out


def track_force_n(track_speed_mps: ArrayLike, ground_speed_mps: ArrayLike,
                  effective_weight_n: ArrayLike, soil: SoilParams, contact_area_m2: float,
                  contact_length_m: float, suction: SaturatedSandParams = NO_SUCTION,
                  saturation: float = 0.0) -> ArrayLike:
    """Soil force on the vehicle from a track at ``track_speed_mps`` over the ground at
    ``ground_speed_mps``, N (+ forward).

    The Wong force is signed like the slip, which is relative to the track's own direction;
    a track running backwards pushes backwards, so the force on the vehicle is that force
    times the sign of the track speed (a stopped track counts as forward: it brakes a
    vehicle moving forward, and pushes one moving backward forward). In saturated sand
    (``saturation`` > 0) the pore suction of the slip velocity strengthens the soil.
    """
    v_t = np.asarray(track_speed_mps, dtype=float)
    suction_pa = 0.0
    if saturation > 0.0 and suction.suction_ratio_per_mps > 0.0:
        pressure_pa = np.maximum(np.asarray(effective_weight_n, dtype=float), 0.0) \
            / contact_area_m2
        suction_pa = pore_suction_pa(v_t - np.asarray(ground_speed_mps, dtype=float),
                                     pressure_pa, saturation, suction)
    h = tractive_force_n(slip(v_t, ground_speed_mps), effective_weight_n, soil,
                         contact_area_m2, contact_length_m, suction_pa)
    out = np.where(v_t >= 0.0, h, -h)
    return float(out) if out.ndim == 0 else out


def track_end_drop_m(track_length_m: float, track_separation_m: float,
                     pitch_rel_rad: float, roll_rel_rad: float) -> float:
    """How far the lowest point of the two tracks hangs below base_link (their middle), m,
    for a hull pitched and rolled this much against the ground under it: half a track length
    and half the tracks' separation out (0 lying flat on it). A tilted hull meets the
    ground with that point first (the simulator's touchdown, the estimator's keel-on-beach
    measurement)."""
    return 0.5 * track_length_m * abs(math.sin(pitch_rel_rad)) \
        + 0.5 * track_separation_m * abs(math.sin(roll_rel_rad))


def effective_weight_n(displacement_n: float, submerged_volume_m3: ArrayLike,
                       slope_rad: ArrayLike, water_density_kgpm3: float,
                       gravity_mps2: float) -> ArrayLike:
    """W_e = (Delta - rho g V) cos(theta), never negative (afloat gives 0), N."""
    if is_scalar(submerged_volume_m3) and is_scalar(slope_rad) \
            and is_scalar(displacement_n):                         # scalar path, same bits
        buoyancy_n = water_density_kgpm3 * gravity_mps2 * float(submerged_volume_m3)
        return max(float(displacement_n) - buoyancy_n, 0.0) * _cos(float(slope_rad))
    buoyancy = water_density_kgpm3 * gravity_mps2 * np.asarray(submerged_volume_m3, dtype=float)
    out = np.maximum(displacement_n - buoyancy, 0.0) * np.cos(slope_rad)
    return float(out) if np.ndim(out) == 0 else out


# ------------------------------------------------------------------ float paths (hot callers)
# The simulator solves each track's speed loop against the soil with a few force evaluations
# (with their derivatives, ``track_force_slopes_f``) per step: these take plain floats and a
# patch with its constants worked out once, and give the same bits as ``slip`` and
# ``track_force_n`` (same operations in the same order; expm1 is numpy's, whose vectorised
# routine is not libm's).

def slip_f(track_speed_mps: float, ground_speed_mps: float,
           min_track_speed_mps: float = MIN_TRACK_SPEED_MPS) -> float:
    """``slip`` of two floats, without the scalar/array dispatch."""
    denom = max(abs(track_speed_mps), min_track_speed_mps) * (
        1.0 if track_speed_mps >= 0.0 else -1.0)
    return min(max((track_speed_mps - ground_speed_mps) / denom, -1.0), 1.0)


def _shear_development_f(slip_abs: float, contact_length_m: float,
                         shear_modulus_m: float) -> float:
    """``shear_development`` of one float |i| >= 0."""
    if shear_modulus_m <= 1e-9:
        return 1.0 if slip_abs > 0.0 else 0.0
    x = slip_abs * contact_length_m / shear_modulus_m
    return x / 2.0 if x < 1e-6 else 1.0 + float(_expm1(-x)) / x   # numpy's expm1: same bits


class TrackPatch:
    """One track's contact patch for ``track_force_f``: the arguments of ``track_force_n``
    (weight, soil, area, length, suction, saturation) with tan(phi), the cohesion's share
    and the contact pressure worked out once."""

    __slots__ = ('weight_n', 'cohesion_n', 'tan_phi', 'area_m2', 'length_m', 'shear_modulus_m',
                 'saturation', 'suction_ratio', 'max_suction_pa', 'pressure_pa', 'suction_on')

    def __init__(self, weight_n: float, soil: SoilParams, contact_area_m2: float,
                 contact_length_m: float, suction: SaturatedSandParams = NO_SUCTION,
                 saturation: float = 0.0) -> None:
        self.weight_n = max(float(weight_n), 0.0)
        self.cohesion_n = contact_area_m2 * soil.cohesion_pa
        self.tan_phi = _tan(soil.friction_angle_rad)
        self.area_m2 = contact_area_m2
        self.length_m = contact_length_m
        self.shear_modulus_m = soil.shear_modulus_m
        self.suction_on = saturation > 0.0 and suction.suction_ratio_per_mps > 0.0
        self.saturation = min(max(float(saturation), 0.0), 1.0)
        self.suction_ratio = suction.suction_ratio_per_mps
        self.max_suction_pa = suction.max_pore_suction_pa
        self.pressure_pa = self.weight_n / contact_area_m2

    def strength_n(self, suction_pa: float = 0.0) -> float:
        """``max_traction_n`` of the patch with this pore suction, N."""
        normal = self.weight_n + self.area_m2 * suction_pa if suction_pa else self.weight_n
        return self.cohesion_n + normal * self.tan_phi


_TAN_OF: dict[float, float] = {}
_COS_OF: dict[float, float] = {}


def _cos(angle_rad: float) -> float:
    """float(np.cos(angle)), remembered per angle (numpy's cos is not libm's; the slopes the
    callers ask for are few)."""
    cos_angle = _COS_OF.get(angle_rad)
    if cos_angle is None:
        if len(_COS_OF) > 1024:
            _COS_OF.clear()
        cos_angle = _COS_OF[angle_rad] = float(np.cos(angle_rad))
    return cos_angle


def _tan(phi_rad: float) -> float:
    """float(np.tan(phi)), remembered per angle (numpy's tan is not libm's)."""
    tan_phi = _TAN_OF.get(phi_rad)
    if tan_phi is None:
        tan_phi = _TAN_OF[phi_rad] = float(np.tan(phi_rad))
    return tan_phi


def track_force_f(patch: TrackPatch, track_speed_mps: float, ground_speed_mps: float) -> float:
    """``track_force_n`` of one track in floats (same bits), N (+ forward).

    ``slip_f`` and ``_shear_development_f`` written out (the soil solve calls this ~25 times
    a step on the sand: the two calls were a third of its time); the same operations in the
    same order."""
    v_t = track_speed_mps
    if v_t >= 0.0:                           # slip_f: max(|v|, 0.05) x sign, exact either way
        i = (v_t - ground_speed_mps) / (v_t if v_t > MIN_TRACK_SPEED_MPS
                                        else MIN_TRACK_SPEED_MPS)
    else:
        i = (v_t - ground_speed_mps) / -(-v_t if -v_t > MIN_TRACK_SPEED_MPS
                                         else MIN_TRACK_SPEED_MPS)
    i = -1.0 if i < -1.0 else (1.0 if i > 1.0 else i)
    w = patch.weight_n
    if i == 0.0 or w <= 0.0:                 # sign(i) x 0 strength: signed zeros as numpy's
        h = 0.0 if i >= 0.0 else -0.0
        return h if v_t >= 0.0 else -h
    normal = w
    if patch.suction_on:
        s = patch.saturation * min(patch.suction_ratio * abs(v_t - ground_speed_mps)
                                   * patch.pressure_pa, patch.max_suction_pa)
        if s:
            normal = w + patch.area_m2 * s
    strength = patch.cohesion_n + normal * patch.tan_phi
    slip_abs = i if i > 0.0 else -i
    if patch.shear_modulus_m <= 1e-9:
        dev = 1.0 if slip_abs > 0.0 else 0.0
    else:
        x = slip_abs * patch.length_m / patch.shear_modulus_m
        dev = x / 2.0 if x < 1e-6 else 1.0 + float(_expm1(-x)) / x   # numpy's expm1
    h = strength * dev if i > 0.0 else -strength * dev
    return h if v_t >= 0.0 else -h


def track_force_slopes_f(patch: TrackPatch, track_speed_mps: float,
                         ground_speed_mps: float) -> tuple[float, float, float]:
    """``track_force_f`` (the same bits) and its analytic derivatives: (force N, d force /
    d track speed N s/m, d force / d ground speed N s/m).

    The simulator's soil solve takes Newton steps on the track speed and linearises the force
    in the ground speed: one call here instead of a force and two probes. Where the slip is
    clipped (|i| = 1) only the pore suction's share varies; at no slip the derivative is the
    bracket's slope there (the force is odd and smooth through i = 0)."""
    v_t = track_speed_mps
    slip_mps = v_t - ground_speed_mps
    if v_t >= 0.0:                           # as track_force_f
        held = not v_t > MIN_TRACK_SPEED_MPS
        denom = MIN_TRACK_SPEED_MPS if held else v_t
    else:
        held = not -v_t > MIN_TRACK_SPEED_MPS
        denom = -(MIN_TRACK_SPEED_MPS if held else -v_t)
    i = slip_mps / denom
    di_dg = -1.0 / denom
    di_dv = -di_dg if held else (1.0 - i) / denom       # d/dv of (v - g) / v: g / v^2
    if i < -1.0 or i > 1.0:
        i = -1.0 if i < -1.0 else 1.0
        di_dv = di_dg = 0.0
    w = patch.weight_n
    if w <= 0.0:
        h = 0.0 if i >= 0.0 else -0.0
        return (h if v_t >= 0.0 else -h), 0.0, 0.0
    normal, ds_dv = w, 0.0
    if patch.suction_on:
        demand = patch.suction_ratio * abs(slip_mps) * patch.pressure_pa
        s = patch.saturation * min(demand, patch.max_suction_pa)
        if s:
            normal = w + patch.area_m2 * s
        if demand < patch.max_suction_pa:
            ds_dv = patch.saturation * patch.suction_ratio * patch.pressure_pa * (
                1.0 if slip_mps > 0.0 else -1.0 if slip_mps < 0.0 else 0.0)
    strength = patch.cohesion_n + normal * patch.tan_phi
    dstrength_dv = patch.area_m2 * ds_dv * patch.tan_phi     # d/dg: the opposite
    slip_abs = i if i > 0.0 else -i
    if patch.shear_modulus_m <= 1e-9:
        dev = 1.0 if slip_abs > 0.0 else 0.0
        ddev_da = 0.0
    else:
        x = slip_abs * patch.length_m / patch.shear_modulus_m    # as track_force_f
        if x < 1e-6:
            dev = x / 2.0
        else:
            e = float(_expm1(-x))
            dev = 1.0 + e / x
        # d dev / dx = -(e + x (e + 1)) / x^2, its series where that cancels
        ddev_dx = 0.5 - x / 3.0 + x * x / 8.0 if x < 1e-3 else -(e + x * (e + 1.0)) / (x * x)
        ddev_da = ddev_dx * patch.length_m / patch.shear_modulus_m
    if i == 0.0:
        h = 0.0 if i >= 0.0 else -0.0        # sign(i) x ...: as track_force_f
        dh_dv, dh_dg = strength * ddev_da * di_dv, strength * ddev_da * di_dg
    else:
        sign = 1.0 if i > 0.0 else -1.0
        h = strength * dev if i > 0.0 else -strength * dev
        shear = strength * ddev_da
        dh_dv = sign * dstrength_dv * dev + shear * di_dv
        dh_dg = -sign * dstrength_dv * dev + shear * di_dg
    if v_t >= 0.0:
        return h, dh_dv, dh_dg
    return -h, -dh_dv, -dh_dg
