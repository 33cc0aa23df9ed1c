"""The horizontal forces on the DUKW-Ling, one pure function per physical effect (ROS-free).

Each effect returns its terms as ``Wrench`` records in body axes (X forward, Y left, N yaw,
with the derivatives the implicit solve needs); ``sum_wrenches`` adds them in one place, in
the order they are given. A new force is a new function returning wrenches, appended to the
list ``SimCore`` sums (``SimCore._body_forces``).

A wrench names only the components its effect has (the others are None, not 0.0), so the sum
adds exactly the terms the effect contributes: adding a 0.0 would flip a signed zero and change
the last bit of results that are recorded in the golden bags.
"""
from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numpy as np

from dukw_sim.params import LandParams, MooringParams, SurfParams, WaterParams, WaveParams
from dukw_sim.world import WaterSample
from dukw_model.fast_numpy import (
    clip as _clip, dot as _dot, new_tuple as _new_tuple, operand as _operand, sum_of as _sum_of)

_ROLL_EPS_MPS = 0.005          # regularisation of Coulomb rolling resistance
_FRICTION_EPS_MPS = 0.02       # of drivetrain friction
_BREAKAWAY_MPS = 0.05          # below this track speed the breakaway friction applies
LATERAL_POINTS = 5             # points along each track for the lateral resistance
_ZERO, _ONE = _operand(0.0), _operand(1.0)   # per-step ufunc operands


class Wrench(NamedTuple):
    """One term of the horizontal force in body axes; None where the effect has no part.

    x_n, y_n, n_nm: surge force, sway force, yaw moment. dx_du, dy_dv, dn_dr: their
    derivatives by surge speed, sway speed and yaw rate (N s/m, N m s/rad). A NamedTuple
    (a dozen are made every step, and the sum walks their components in order).
    """

    x_n: float | None = None
    y_n: float | None = None
    n_nm: float | None = None
    dx_du: float | None = None
    dy_dv: float | None = None
    dn_dr: float | None = None


# Wrench(x_n, y_n, n_nm, dx_du, dy_dv, dn_dr) from the six values in order (None: no part),
# without the NamedTuple's Python __new__ (a dozen terms are made every step on the sand)
_wrench = functools.partial(_new_tuple, Wrench)


class BodyForces(NamedTuple):
    """The sum of all wrenches of a step (body axes), with its derivatives."""

    x_n: float
    y_n: float
    n_nm: float
    dx_du: float
    dy_dv: float
    dn_dr: float


def sum_wrenches(terms: list[Wrench]) -> BodyForces:
    """Add the terms in order; the first term's components start the sums, absent ones 0.0."""
    total = []
    for column in zip(*terms, strict=True):   # a component of every term, in their order
        acc = 0.0 if column[0] is None else column[0]
        for value in column[1:]:
            if value is not None:
                acc += value
        total.append(acc)
    return _new_tuple(BodyForces, total)


class StripSums(NamedTuple):
    """Sums over the hull strips weighted by their immersed section areas a_i (m^2): of 1 and
    of the water's velocity (vx, vy) and acceleration (ax, ay) at the strips (odom), each
    also times the strips' body x_i, y_i, x_i^2 and y_i^2. The buoyancy, the wave forces,
    their moments (each direction with its own inertia coefficient) and the water's yaw rate
    (each direction weighted by its drag) are all linear in these: one matrix product per
    step (``strip_sums``) gives them all (the x2_, y2_ kinematic sums come with it, unused)."""

    area_m2: float
    vx: float
    vy: float
    ax: float
    ay: float
    area_x_m3: float
    x_vx: float
    x_vy: float
    x_ax: float
    x_ay: float
    area_y_m3: float
    y_vx: float
    y_vy: float
    y_ax: float
    y_ay: float
    area_x2_m4: float
    x2_vx: float
    x2_vy: float
    x2_ax: float
    x2_ay: float
    area_y2_m4: float
    y2_vx: float
    y2_vy: float
    y2_ax: float
    y2_ay: float


def strip_basis(station_x_m: np.ndarray, station_y_m: np.ndarray) -> np.ndarray:
    """The strips' (5, N) rows 1, x, y, x^2, y^2 that ``strip_sums`` weights (keep it)."""
    x = np.asarray(station_x_m, dtype=float)
    y = np.asarray(station_y_m, dtype=float)
    return np.ascontiguousarray(np.vstack([np.ones_like(x), x, y, x * x, y * y]))


def strip_sums(areas_m2: np.ndarray, water: WaterSample, basis: np.ndarray) -> StripSums:
    """The area-weighted sums of ``StripSums`` of the N strips (``basis`` from
    ``strip_basis``; the water's kinematics at the strips are its first N points)."""
    n = areas_m2.size
    kin = np.array((basis[0], water.velocity_x_mps[:n], water.velocity_y_mps[:n],
                    water.accel_x_mps2[:n], water.accel_y_mps2[:n]))
    return _new_tuple(StripSums, _dot(basis * areas_m2, kin.T).ravel().tolist())   # dot: @'s bits


def _sums_of(sums: StripSums | None, areas_m2: np.ndarray, water: WaterSample,
             station_x_m: np.ndarray | None = None,
             station_y_m: np.ndarray | None = None) -> StripSums:
    """The given sums, else those of these strips (at the body's origin if not placed)."""
    if sums is not None:
        return sums
    if station_x_m is None:
        station_x_m = station_y_m = np.zeros(areas_m2.size)
    return strip_sums(areas_m2, water, strip_basis(station_x_m, station_y_m))


class Immersion(NamedTuple):
    """The hull strips in the water: their buoyancy, the volume and its afloat share (each
    strip's buoyancy is rho g l a_i; nothing asks for it, so it is not made every step)."""

    buoyancy_n: float
    volume_m3: float
    fraction: float             # submerged share of the afloat volume, 0..1


def immersion(areas_m2: np.ndarray, strip_length_m: float, rho_g: float,
              afloat_volume_m3: float, area_sum_m2: float | None = None) -> Immersion:
    """Buoyancy of the hull strips with these immersed section areas (``area_sum_m2``:
    their sum, if the caller has it)."""
    if area_sum_m2 is None:
        area_sum_m2 = float(areas_m2.sum())
    buoy = rho_g * strip_length_m * area_sum_m2
    volume = buoy / rho_g
    return _new_tuple(Immersion, (buoy, volume, min(volume / afloat_volume_m3, 1.0)))


class WaveForcing(NamedTuple):
    """Wave force on the hull in odom (N) and the mean water velocity at it (m/s)."""

    fx_n: float
    fy_n: float
    water_u_mps: float
    water_v_mps: float


def wave_forcing(calm: bool, areas_m2: np.ndarray, strip_length_m: float, water: WaterSample,
                 waves: WaveParams, rho_kgpm3: float, rho_g: float, amplitude_sq_m2: float,
                 beam_m: float, imm: Immersion, sums: StripSums | None = None) -> WaveForcing:
    """Froude-Krylov + diffraction on the hull strips, less the mean drift (shoreward).
    ``sums``: the strips' ``strip_sums`` if the caller has them."""
    if calm:
        return WaveForcing(0.0, 0.0, 0.0, 0.0)
    sums = _sums_of(sums, areas_m2, water)
    cm_rho_l = waves.surge_inertia_coeff * rho_kgpm3 * strip_length_m
    fwx = cm_rho_l * sums.ax
    fwy = cm_rho_l * sums.ay
    drift = (waves.drift_force_coeff * 0.5 * rho_g
             * amplitude_sq_m2
             * beam_m * imm.fraction)
    fwx -= drift                                    # shoreward, with the waves
    if imm.volume_m3 > 1e-9:
        wu = sums.vx / sums.area_m2
        wv = sums.vy / sums.area_m2
    else:
        wu = wv = 0.0
    return _new_tuple(WaveForcing, (fwx, fwy, wu, wv))


def water_yaw_rate_rps(areas_m2: np.ndarray, water: WaterSample, station_x_m: np.ndarray,
                       station_y_m: np.ndarray, yaw_cs: tuple, surge_to_sway_drag: float = 1.0,
                       sums: StripSums | None = None) -> float:
    """The water's own yaw rate over the hull: the rotation of the wave particle velocity at
    the immersed strips that the hull's drag acts against (body axes), rad/s.

    The hull drag acts on the velocity relative to the water, strip by strip; in a
    short-crested sea the transverse water velocity differs along the hulls (and the surge
    velocity between them), so the yaw damping acts on r minus this rate, as the surge and sway
    drag act on u and v minus the water's mean velocity (``wave_forcing``). Each strip's
    relative velocity is weighted by the drag it meets in that direction: the transverse
    (cross-flow) one by the sway drag, the longitudinal one by ``surge_to_sway_drag`` times
    it (1: the least-squares rotation, immersed area as weight). ``sums``: the strips'
    ``strip_sums`` if the caller has them."""
    sums = _sums_of(sums, areas_m2, water, station_x_m, station_y_m)
    w = surge_to_sway_drag
    weight = sums.area_x2_m4 + w * sums.area_y2_m4          # sum of a (x^2 + w y^2)
    if weight <= 1e-12:
        return 0.0
    c, s = yaw_cs
    # sum of a (x vb - w y ub), with body-axes water velocity ub = c vx + s vy, vb = -s vx + c vy
    return (c * (sums.x_vy - w * sums.y_vx) - s * (sums.x_vx + w * sums.y_vy)) / weight


class WaveMoments(NamedTuple):
    """Moments about the centre of gravity of the strips' wave forces: yaw (odom z), roll and
    pitch (body x, y), N m; and the strips' transverse force beyond the total force of
    ``wave_forcing`` (which takes the surge inertia coefficient in every direction), odom, N."""

    yaw_nm: float
    roll_nm: float
    pitch_nm: float
    extra_fx_n: float = 0.0
    extra_fy_n: float = 0.0


def wave_moments(calm: bool, areas_m2: np.ndarray, strip_length_m: float, water: WaterSample,
                 waves: WaveParams, rho_kgpm3: float, station_x_m: np.ndarray,
                 station_y_m: np.ndarray, yaw_cs: tuple, lever_z_m: float,
                 sway_inertia_coeff: float | None = None,
                 sums: StripSums | None = None) -> WaveMoments:
    """Each strip's Froude-Krylov + diffraction force acting at the strip: its horizontal
    offset from the centre of gravity gives the yaw moment, its height ``lever_z_m`` relative
    to it (< 0: below) the roll and pitch moments. In a short-crested sea the transverse
    acceleration differs along the hulls, so the yaw moment does not vanish with the vehicle's
    symmetry.

    Morison's inertia force per strip is C_m rho V a with C_m = 1 + C_a in each direction:
    along the hulls C_m = ``waves.surge_inertia_coeff`` (1 + the surge added-mass ratio),
    across them ``sway_inertia_coeff`` (1 + the sway added-mass ratio: the added mass the
    body's sway inertia carries is the same that the accelerating water exerts; None: the
    surge one). The transverse force beyond the surge coefficient's is returned (odom) for
    the total force. ``sums``: the strips' ``strip_sums`` if the caller has them."""
    if calm:
        return WaveMoments(0.0, 0.0, 0.0)
    sums = _sums_of(sums, areas_m2, water, station_x_m, station_y_m)
    c, s = yaw_cs
    rho_l = rho_kgpm3 * strip_length_m
    cm_x = waves.surge_inertia_coeff
    cm_y = cm_x if sway_inertia_coeff is None else sway_inertia_coeff
    # the strips' body-axes accelerations, area-weighted: along = c ax + s ay, across =
    # -s ax + c ay; the force along is cm_x rho l along, across cm_y rho l across; the yaw
    # moment sum of x f_across - y f_along (the cross product is the same in body axes)
    across = -s * sums.ax + c * sums.ay
    fx_body = cm_x * rho_l * (c * sums.ax + s * sums.ay)
    fy_body = cm_y * rho_l * across
    yaw = rho_l * (cm_y * (c * sums.x_ay - s * sums.x_ax)
                   - cm_x * (c * sums.y_ax + s * sums.y_ay))
    extra = (cm_y - cm_x) * rho_l * across
    # REP 103: a force to port below the centre of gravity lifts the port side (+ roll); a
    # force forward below it lifts the bow (- pitch)
    return _new_tuple(WaveMoments, (yaw, -lever_z_m * fy_body, lever_z_m * fx_body, -s * extra,
                                    c * extra))


def track_wetness(water_over_ground_m: np.ndarray, track_height_m: float) -> float:
    """Share of the tracks' height under water, 0 (dry sand) .. 1 (the tracks covered),
    mean of the given points along the tracks."""
    if water_over_ground_m.size == 0:
        return 0.0
    share = _clip(water_over_ground_m / track_height_m, _ZERO, _ONE)
    return float(_sum_of(share)) / share.size                    # np.mean, same bits


def saturated_share(water_over_ground_m: np.ndarray) -> float:
    """Share of the given points along the tracks with water standing over the sand: there
    the sand under the tracks is saturated, 0 (dry beach) .. 1 (all under the surf)."""
    if water_over_ground_m.size == 0:
        return 0.0
    return float(np.count_nonzero(np.greater(water_over_ground_m, _ZERO))) \
        / water_over_ground_m.size


def surf_resistance(w_eff_n: float, wetness: float, wave_height_m: float, ground_mps: tuple,
                    surf: SurfParams, half_sep_m: float, other_pull_n: float = 0.0
                    ) -> list[Wrench]:
    """Motion resistance of the sand the surf's waves liquefy (sinkage and bulldozing): a
    Coulomb resistance growing with the weight on the tracks, with the share of the tracks
    under water and with the waves' height (the depth of the wave-induced liquefaction grows
    with the wave's pressure on the bed). The tow tests' load cell measured the whole pull
    (this, the rolling resistance and the slope's gravity against the motion:
    ``other_pull_n``) up to ``surf.max_resistance_n``; that bounds the sum."""
    liquefied = wave_height_m / surf.reference_wave_height_m
    total_n = min(surf.wet_motion_resistance_coeff * liquefied * wetness * w_eff_n,
                  surf.max_resistance_n - other_pull_n)
    if total_n <= 0.0:
        return []
    return _coulomb_per_track(total_n / 2.0, ground_mps, half_sep_m)


def mooring_force(stiffness_n_per_m: float, damping_n_per_mps: float, offset_m: tuple,
                  velocity_mps: tuple, lever_m: tuple) -> tuple[float, float, float]:
    """A line held at a point of the vehicle (a spring and a damper to a fixed anchor):
    force in odom at that point's offset and velocity, and its yaw moment about the centre
    of gravity (lever = the point's odom offset from it). Returns (fx, fy, moment)."""
    fx = -stiffness_n_per_m * offset_m[0] - damping_n_per_mps * velocity_mps[0]
    fy = -stiffness_n_per_m * offset_m[1] - damping_n_per_mps * velocity_mps[1]
    return fx, fy, lever_m[0] * fy - lever_m[1] * fx


def line_force(stiffness_n_per_m: float, damping_n_per_mps: float, length_m: float,
               offset_m: tuple, velocity_mps: tuple, lever_m: tuple) -> tuple[float, float, float]:
    """A line of unstretched ``length_m`` from a holder's hand to a point of the vehicle
    (offset and velocity of the point from the hand, odom): it pulls the point towards the
    hand with the stretch's spring and the stretching rate's damper, never pushes, and is
    slack while shorter than its length. Returns (fx, fy, yaw moment about the centre of
    gravity, lever = the point's odom offset from it)."""
    distance_m = math.hypot(offset_m[0], offset_m[1])
    if distance_m <= length_m:
        return 0.0, 0.0, 0.0
    ex, ey = offset_m[0] / distance_m, offset_m[1] / distance_m
    stretch_rate = velocity_mps[0] * ex + velocity_mps[1] * ey
    tension_n = max(stiffness_n_per_m * (distance_m - length_m)
                    + damping_n_per_mps * stretch_rate, 0.0)
    fx, fy = -tension_n * ex, -tension_n * ey
    return fx, fy, lever_m[0] * fy - lever_m[1] * fx


def mooring_anchor(moor: MooringParams, x_m: float, y_m: float,
                   yaw_rad: float) -> tuple[float, float]:
    """Where the restraint is held (odom), for a vehicle at this pose at the start: the
    attachment point itself ('spring'), or the holder's hand line_holder_distance_m beyond
    it along the hull's axis, outward from the end the line is made fast to ('line')."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    reach = moor.attach_x_m
    if moor.model == 'line':
        reach += math.copysign(moor.line_holder_distance_m, moor.attach_x_m)
    return x_m + c * reach, y_m + s * reach


def mooring(moor: MooringParams, x_m: float, y_m: float, yaw_rad: float, u_mps: float,
            v_mps: float, r_rps: float, anchor: tuple) -> tuple[float, float, float]:
    """The restraint's force on a vehicle at this pose and speed (body u, v, r), held at
    ``anchor`` (``mooring_anchor``); (fx, fy) odom and yaw moment."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    lever = (c * moor.attach_x_m, s * moor.attach_x_m)
    point = (x_m + lever[0], y_m + lever[1])
    vel = (c * u_mps - s * v_mps - r_rps * lever[1], s * u_mps + c * v_mps + r_rps * lever[0])
    offset = (point[0] - anchor[0], point[1] - anchor[1])
    if moor.model == 'line':
        return line_force(moor.line_stiffness_n_per_m, moor.line_damping_n_per_mps,
                          moor.line_holder_distance_m + moor.line_slack_m, offset, vel, lever)
    return mooring_force(moor.stiffness_n_per_m, moor.damping_n_per_mps, offset, vel, lever)


def drivetrain_friction_n(friction_n: float, track_speed_mps: float, ref_mps: float,
                          breakaway_ratio: float) -> float:
    """Friction of one track's drivetrain (breakaway near standstill), against the reference."""
    fric = friction_n
    if abs(track_speed_mps) < _BREAKAWAY_MPS:
        fric *= 1.0 + (breakaway_ratio - 1.0) * (
            1.0 - abs(track_speed_mps) / _BREAKAWAY_MPS)
    fric *= math.tanh(ref_mps / _FRICTION_EPS_MPS)
    return fric


def track_paddle_n(paddle_coeff_n_per_mps2: float, ref_mps: float, u_rel_mps: float,
                   immersion_share: float) -> float:
    """Force of a track paddling through the water (its speed relative to the water)."""
    rel = ref_mps - u_rel_mps
    return paddle_coeff_n_per_mps2 * rel * abs(rel) * immersion_share


def paddle_wrench(paddle_n: list[float], half_sep_m: float) -> Wrench:
    """Both tracks' paddle forces on the vehicle."""
    return _wrench((paddle_n[0] + paddle_n[1], None, (paddle_n[1] - paddle_n[0]) * half_sep_m,
                    None, None, None))


def rolling_resistance(w_eff_n: float, ground_mps: tuple, land: LandParams,
                       half_sep_m: float) -> list[Wrench]:
    """Coulomb rolling resistance of each track (regularised), port then starboard."""
    return _coulomb_per_track(land.rolling_resistance_coeff * w_eff_n / 2.0, ground_mps,
                              half_sep_m)


def _coulomb_per_track(roll_n: float, ground_mps: tuple, half_sep_m: float) -> list[Wrench]:
    """A Coulomb resistance of ``roll_n`` on each track against its ground speed."""
    out = []
    for i, sign in ((0, -1.0), (1, 1.0)):
        th = math.tanh(ground_mps[i] / _ROLL_EPS_MPS)
        f = -roll_n * th
        dth = roll_n * (1.0 - th * th) / _ROLL_EPS_MPS
        out.append(_wrench((f, None, sign * f * half_sep_m, -dth, None,
                            -(dth * half_sep_m ** 2))))
    return out


def lateral_resistance(w_eff_n: float, sway_mps: float, yaw_rate_rps: float,
                       points_m: list[float], land: LandParams,
                       weight_n: float) -> list[Wrench]:
    """Sideways soil friction and damping at points along the tracks (skid while turning)."""
    lat_n = land.lateral_friction_coeff * w_eff_n / LATERAL_POINTS
    v_ref = land.lateral_slip_speed_mps
    lat_c = land.lateral_damping_n_per_mps * w_eff_n / weight_n / LATERAL_POINTS
    out = []
    for s_j in points_m:
        th = math.tanh((sway_mps + yaw_rate_rps * s_j) / v_ref)
        f = -lat_n * th - lat_c * (sway_mps + yaw_rate_rps * s_j)
        d = lat_n * (1.0 - th * th) / v_ref + lat_c
        out.append(_wrench((None, f, f * s_j, None, -d, -(d * s_j * s_j))))
    return out


def slope_gravity(weight_n: float, buoyancy_n: float, gradient: float, cos_yaw: float,
                  sin_yaw: float) -> list[Wrench]:
    """Gravity along the slope, (Delta - B) sin(theta) downhill, odom -> body."""
    if gradient == 0.0:
        return []
    down = -(weight_n - buoyancy_n) * gradient / math.sqrt(1.0 + gradient * gradient)
    return [_wrench((cos_yaw * down, -sin_yaw * down, None, None, None, None))]


def propulsion(thrust_n: list[float], walk_ratio: float, prop_x_m: float,
               half_sep_m: float) -> list[Wrench]:
    """The two propellers' thrust and the sideways propeller walk."""
    walk = -walk_ratio * (thrust_n[0] + thrust_n[1])
    return [_wrench((thrust_n[0] + thrust_n[1], None, (thrust_n[1] - thrust_n[0]) * half_sep_m,
                     None, None, None)),
            _wrench((None, walk, walk * prop_x_m, None, None, None))]


def strip_yaw_added_inertia_kg_m2(sway_added_mass_kg: float, station_x_m: np.ndarray) -> float:
    """Strip theory's yaw added inertia: the sway added mass spread evenly over the strips
    times their lever arm squared, sum a22(x) x^2 dx (Newman, Marine Hydrodynamics, 1977,
    ch. 7), kg m^2. The same added mass the strips' wave inertia force carries across the
    hulls (``wave_moments``), so a free hull turns with the water's cross-flow gradient."""
    return sway_added_mass_kg * float(np.mean(np.square(station_x_m)))


def yaw_linear_drag_nm_per_rps(wat: WaterParams, surge_rel_mps: float) -> float:
    """Linear yaw damping at a surge speed through the water: the part at zero speed
    (``yaw_linear_drag_nm_per_rps``) plus the hulls' and keels' lift, growing with the
    forward speed (slender-body theory, N_r ~ rho U L^3: Clarke, Gedling and Hine 1983;
    ``yaw_lift_damping_nm_s_per_m``), N m s/rad."""
    return (wat.yaw_linear_drag_nm_per_rps
            + wat.yaw_lift_damping_nm_s_per_m * abs(surge_rel_mps))


def hydrodynamic_drag(u_rel_mps: float, v_rel_mps: float, yaw_rate_rps: float,
                      fraction: float, wat: WaterParams) -> Wrench:
    """Linear + quadratic hull drag through the water, scaled by the submerged share; the
    linear yaw damping grows with the surge speed (``yaw_linear_drag_nm_per_rps``)."""
    yaw_linear_nm_per_rps = yaw_linear_drag_nm_per_rps(wat, u_rel_mps)
    return _wrench((       # x_n, y_n, n_nm, dx_du, dy_dv, dn_dr
        -(wat.surge_linear_drag_n_per_mps * u_rel_mps
          + wat.surge_quadratic_drag_n_per_mps2 * abs(u_rel_mps) * u_rel_mps) * fraction,
        -(wat.sway_linear_drag_n_per_mps * v_rel_mps
          + wat.sway_quadratic_drag_n_per_mps2 * abs(v_rel_mps) * v_rel_mps) * fraction,
        -(yaw_linear_nm_per_rps * yaw_rate_rps
          + wat.yaw_quadratic_drag_nm_per_rps2 * abs(yaw_rate_rps) * yaw_rate_rps) * fraction,
        -(wat.surge_linear_drag_n_per_mps
          + 2.0 * wat.surge_quadratic_drag_n_per_mps2 * abs(u_rel_mps)) * fraction,
        -(wat.sway_linear_drag_n_per_mps
          + 2.0 * wat.sway_quadratic_drag_n_per_mps2 * abs(v_rel_mps)) * fraction,
        -(yaw_linear_nm_per_rps
          + 2.0 * wat.yaw_quadratic_drag_nm_per_rps2 * abs(yaw_rate_rps)) * fraction))


def odom_force(fx_n: float, fy_n: float, moment_nm: float, cos_yaw: float,
               sin_yaw: float) -> Wrench:
    """A horizontal force given in odom (waves, a tow line), in body axes."""
    return _wrench((cos_yaw * fx_n + sin_yaw * fy_n, -sin_yaw * fx_n + cos_yaw * fy_n, moment_nm,
                    None, None, None))
