"""dukw_sim.forces: the per-effect force terms and their one sum."""
import dataclasses
import math

import numpy as np
import pytest

from dukw_sim.core import SimCore
from dukw_common.config import ConfigError
from dukw_sim.forces import (Wrench, hydrodynamic_drag, lateral_resistance, mooring,
                             mooring_anchor,
                             odom_force, propulsion, rolling_resistance, slope_gravity,
                             saturated_share, strip_basis, strip_sums,
                             strip_yaw_added_inertia_kg_m2,
                             sum_wrenches, surf_resistance, track_wetness, water_yaw_rate_rps,
                             wave_moments, yaw_linear_drag_nm_per_rps)
from dukw_sim.world import WaterSample

PARAMS = SimCore.from_config().params
HALF_SEP_M = 0.6
WEIGHT_N = 2900.0


def total(terms: list[Wrench], name: str) -> float:
    return getattr(sum_wrenches(terms), name)


def test_sum_adds_only_the_components_a_term_has():
    terms = [Wrench(x_n=-0.0, n_nm=2.0), Wrench(y_n=-0.0, n_nm=3.0, dx_du=-4.0),
             Wrench(x_n=1.5)]
    forces = sum_wrenches(terms)
    assert (forces.x_n, forces.y_n, forces.n_nm, forces.dx_du) == (1.5, 0.0, 5.0, -4.0)
    # a sign of zero survives where no later term has the component
    assert math.copysign(1.0, sum_wrenches(terms[:2]).x_n) == -1.0
    # absent components of the first term start at +0.0, as a fresh sum does
    assert math.copysign(1.0, sum_wrenches(terms[:2]).y_n) == 1.0


def test_sum_keeps_the_order_of_the_terms():
    big, small = 1e16, 1.0
    forward = sum_wrenches([Wrench(x_n=big), Wrench(x_n=small), Wrench(x_n=small)]).x_n
    assert forward == (big + small) + small
    assert forward != big + (small + small)


@pytest.mark.parametrize('effect, speed_arg, force, derivative', [
    (lambda u: [hydrodynamic_drag(u, 0.3, 0.1, 0.8, PARAMS.water)], 'u', 'x_n', 'dx_du'),
    (lambda v: [hydrodynamic_drag(0.4, v, 0.1, 0.8, PARAMS.water)], 'v', 'y_n', 'dy_dv'),
    (lambda r: [hydrodynamic_drag(0.4, 0.3, r, 0.8, PARAMS.water)], 'r', 'n_nm', 'dn_dr'),
    (lambda v: lateral_resistance(1500.0, v, 0.2, [-0.4, 0.0, 0.4], PARAMS.land, WEIGHT_N),
     'v', 'y_n', 'dy_dv'),
    (lambda r: lateral_resistance(1500.0, 0.05, r, [-0.4, 0.0, 0.4], PARAMS.land, WEIGHT_N),
     'r', 'n_nm', 'dn_dr'),
])
def test_derivatives_match_the_forces(effect, speed_arg, force, derivative):
    for speed in (-0.7, -0.02, 0.01, 0.5):
        step = 1e-6
        numeric = (total(effect(speed + step), force)
                   - total(effect(speed - step), force)) / (2.0 * step)
        assert total(effect(speed), derivative) == pytest.approx(numeric, rel=1e-4, abs=1e-3)


def test_rolling_resistance_opposes_motion_and_turning():
    moving = sum_wrenches(rolling_resistance(2000.0, (0.5, 0.5), PARAMS.land, HALF_SEP_M))
    assert moving.x_n == pytest.approx(-PARAMS.land.rolling_resistance_coeff * 2000.0)
    assert moving.n_nm == pytest.approx(0.0)
    turning = sum_wrenches(rolling_resistance(2000.0, (-0.3, 0.3), PARAMS.land, HALF_SEP_M))
    assert turning.x_n == pytest.approx(0.0)
    assert turning.n_nm < 0.0          # turning left (starboard forward) is resisted


def test_drag_opposes_the_water_relative_motion_and_vanishes_ashore():
    drag = hydrodynamic_drag(0.8, -0.2, 0.3, 1.0, PARAMS.water)
    assert drag.x_n < 0.0 and drag.y_n > 0.0 and drag.n_nm < 0.0
    ashore = hydrodynamic_drag(0.8, -0.2, 0.3, 0.0, PARAMS.water)
    assert (ashore.x_n, ashore.y_n, ashore.n_nm) == (0.0, 0.0, 0.0)


def test_slope_gravity_pulls_downhill_with_the_unsupported_weight():
    grad = math.tan(0.1)
    (facing_sea,) = slope_gravity(WEIGHT_N, 900.0, grad, 1.0, 0.0)
    assert facing_sea.x_n == pytest.approx(-(WEIGHT_N - 900.0) * math.sin(0.1))
    (sideways,) = slope_gravity(WEIGHT_N, 900.0, grad, 0.0, 1.0)
    assert sideways.y_n == pytest.approx((WEIGHT_N - 900.0) * math.sin(0.1))
    assert slope_gravity(WEIGHT_N, 900.0, 0.0, 1.0, 0.0) == []


def test_propulsion_turns_with_differential_thrust_and_walks_sideways():
    push, walk = propulsion([100.0, 60.0], 0.05, -1.2, HALF_SEP_M)
    assert push.x_n == 160.0
    assert push.n_nm == pytest.approx(-40.0 * HALF_SEP_M)
    assert walk.y_n == pytest.approx(-0.05 * 160.0)
    assert walk.n_nm == pytest.approx(walk.y_n * -1.2)


def test_odom_force_rotates_into_body_axes():
    yaw = 0.7
    body = odom_force(10.0, 0.0, 3.0, math.cos(yaw), math.sin(yaw))
    assert body.x_n == pytest.approx(10.0 * math.cos(yaw))
    assert body.y_n == pytest.approx(-10.0 * math.sin(yaw))
    assert body.n_nm == 3.0


def _water(accel_x: np.ndarray, accel_y: np.ndarray) -> WaterSample:
    zeros = np.zeros(accel_x.size)
    return WaterSample(zeros, zeros, zeros, accel_x, accel_y)


STATION_X_M = np.array([-1.0, 0.0, 1.0, -1.0, 0.0, 1.0])
STATION_Y_M = np.array([0.4, 0.4, 0.4, -0.4, -0.4, -0.4])
AREAS_M2 = np.full(6, 0.05)


def test_a_uniform_transverse_wave_gives_no_yaw_and_a_gradient_does():
    args = (0.3, PARAMS.waves, 1025.0, STATION_X_M, STATION_Y_M, (1.0, 0.0), -0.11)
    uniform = wave_moments(False, AREAS_M2, 0.3, _water(np.zeros(6), np.full(6, 0.5)),
                           *args[1:])
    assert uniform.yaw_nm == pytest.approx(0.0, abs=1e-9)
    # a force to port below the centre of gravity lifts the port side (REP 103 + roll)
    assert uniform.roll_nm > 0.0
    # the bow pushed to port, the stern to starboard: the bow swings to port (+ yaw)
    twist = wave_moments(False, AREAS_M2, 0.3, _water(np.zeros(6), 0.5 * STATION_X_M),
                         *args[1:])
    mass_per_strip = PARAMS.waves.surge_inertia_coeff * 1025.0 * 0.05 * 0.3
    assert twist.yaw_nm == pytest.approx(mass_per_strip * 0.5 * 4.0)
    assert wave_moments(True, AREAS_M2, 0.3, _water(np.zeros(6), 0.5 * STATION_X_M),
                        *args[1:]) == (0.0, 0.0, 0.0, 0.0, 0.0)


def test_the_sway_inertia_coefficient_scales_the_transverse_force_only():
    """Morison's C_m = 1 + C_a across the hulls: the transverse moments and the force beyond
    the total's surge C_m grow with it, the surge ones do not; at any heading."""
    yaw = 0.7
    cs = (math.cos(yaw), math.sin(yaw))
    args = (PARAMS.waves, 1025.0, STATION_X_M, STATION_Y_M, cs, -0.11)
    cm_x = PARAMS.waves.surge_inertia_coeff
    # water accelerating across the hull (body y) with a gradient along it
    across = 0.5 * STATION_X_M + 0.2
    water = _water(-math.sin(yaw) * across, math.cos(yaw) * across)
    same = wave_moments(False, AREAS_M2, 0.3, water, *args)
    assert (same.extra_fx_n, same.extra_fy_n) == (0.0, 0.0)
    assert wave_moments(False, AREAS_M2, 0.3, water, *args, cm_x) == same
    cm_y = 1.9
    more = wave_moments(False, AREAS_M2, 0.3, water, *args, cm_y)
    assert more.yaw_nm == pytest.approx(same.yaw_nm * cm_y / cm_x)
    assert more.roll_nm == pytest.approx(same.roll_nm * cm_y / cm_x)
    extra_n = (cm_y - cm_x) * 1025.0 * 0.05 * 0.3 * float(across.sum())
    assert more.extra_fx_n == pytest.approx(-math.sin(yaw) * extra_n)
    assert more.extra_fy_n == pytest.approx(math.cos(yaw) * extra_n)
    # water accelerating along the hull: nothing changes
    along = _water(math.cos(yaw) * np.full(6, 0.5), math.sin(yaw) * np.full(6, 0.5))
    base = wave_moments(False, AREAS_M2, 0.3, along, *args)
    surge = wave_moments(False, AREAS_M2, 0.3, along, *args, cm_y)
    assert surge.pitch_nm == pytest.approx(base.pitch_nm) and surge.pitch_nm != 0.0
    assert surge.extra_fy_n == pytest.approx(0.0, abs=1e-9)


def test_a_surge_wave_force_below_the_centre_of_gravity_lifts_the_bow():
    forward = wave_moments(False, AREAS_M2, 0.3, _water(np.full(6, 0.5), np.zeros(6)),
                           PARAMS.waves, 1025.0, STATION_X_M, STATION_Y_M, (1.0, 0.0), -0.11)
    assert forward.pitch_nm < 0.0 and forward.yaw_nm == pytest.approx(0.0, abs=1e-9)


def test_track_wetness_is_the_covered_share_of_the_tracks():
    assert track_wetness(np.array([-0.2, 0.0]), 0.25) == 0.0
    assert track_wetness(np.array([0.125, 0.5]), 0.25) == pytest.approx(0.75)
    assert track_wetness(np.zeros(0), 0.25) == 0.0


def test_saturated_share_counts_the_points_under_water():
    assert saturated_share(np.array([-0.2, 0.0, -0.01])) == 0.0
    assert saturated_share(np.array([0.01, -0.1, 0.3, -0.2])) == pytest.approx(0.5)
    assert saturated_share(np.zeros(0)) == 0.0


def test_surf_resistance_grows_with_wetness_weight_and_waves_within_the_tow_test_bound():
    surf = dataclasses.replace(PARAMS.surf, wet_motion_resistance_coeff=0.2,
                               reference_wave_height_m=0.28)
    h = 0.28
    assert surf_resistance(2000.0, 0.0, h, (0.5, 0.5), surf, HALF_SEP_M) == []
    assert surf_resistance(2000.0, 1.0, 0.0, (0.5, 0.5), surf, HALF_SEP_M) == []   # calm
    half = total(surf_resistance(2000.0, 0.5, h, (0.5, 0.5), surf, HALF_SEP_M), 'x_n')
    full = total(surf_resistance(2000.0, 1.0, h, (0.5, 0.5), surf, HALF_SEP_M), 'x_n')
    assert half == pytest.approx(-200.0, rel=1e-6) and full == pytest.approx(-400.0, rel=1e-6)
    small_waves = total(surf_resistance(2000.0, 1.0, 0.07, (0.5, 0.5), surf, HALF_SEP_M),
                        'x_n')
    assert small_waves == pytest.approx(-100.0, rel=1e-6)
    backwards = total(surf_resistance(2000.0, 1.0, h, (-0.5, -0.5), surf, HALF_SEP_M), 'x_n')
    assert backwards == pytest.approx(400.0, rel=1e-6)
    heavy = dataclasses.replace(surf, wet_motion_resistance_coeff=1.0)
    capped = total(surf_resistance(2894.0, 1.0, h, (0.5, 0.5), heavy, HALF_SEP_M), 'x_n')
    assert capped == pytest.approx(-surf.max_resistance_n, rel=1e-6)
    # the tow line's load cell measured the whole pull: with 300 N of rolling resistance and
    # slope against the motion the wet sand adds at most the rest of the bound
    shared = total(surf_resistance(2894.0, 1.0, h, (0.5, 0.5), heavy, HALF_SEP_M, 300.0),
                   'x_n')
    assert shared == pytest.approx(-(surf.max_resistance_n - 300.0), rel=1e-6)
    assert surf_resistance(2894.0, 1.0, h, (0.5, 0.5), heavy, HALF_SEP_M,
                           surf.max_resistance_n + 1.0) == []


def test_mooring_pulls_back_to_the_anchor_and_turns_about_its_point():
    moor = dataclasses.replace(PARAMS.mooring, model='spring', stiffness_n_per_m=60.0,
                               damping_n_per_mps=0.0, attach_x_m=-1.0)
    anchor = (-1.0, 0.0)
    assert mooring(moor, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, anchor) == pytest.approx((0.0, 0.0, 0.0))
    fx, fy, moment = mooring(moor, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, anchor)
    assert (fx, fy, moment) == pytest.approx((-30.0, 0.0, 0.0))
    # turned to starboard (yaw -0.1), the stern swings to port: the line pulls it back to
    # starboard, a + yaw moment that turns the vehicle back (held at the stern: stable)
    _, fy, moment = mooring(moor, 0.0, 0.0, -0.1, 0.0, 0.0, 0.0, anchor)
    assert fy < 0.0 and moment > 0.0


def _stern_line(**changes) -> object:
    settings = dict(model='line', attach_x_m=-1.0, line_stiffness_n_per_m=300.0,
                    line_damping_n_per_mps=0.0, line_holder_distance_m=1.0, line_slack_m=0.2)
    settings.update(changes)
    return dataclasses.replace(PARAMS.mooring, **settings)


def test_a_line_is_held_beyond_its_end_and_is_slack_within_its_length():
    moor = _stern_line()
    hand = mooring_anchor(moor, 0.0, 0.0, 0.0)
    assert hand == pytest.approx((-2.0, 0.0))             # 1 m astern of the stern fitting
    assert mooring_anchor(_stern_line(attach_x_m=1.2), 0.0, 0.0, math.pi) == pytest.approx(
        (-2.2, 0.0))                                      # bow line, bow to the beach
    # within the 1.2 m line (1 m + 0.2 m slack): no force, however fast it moves
    assert mooring(moor, 0.15, 0.0, 0.0, 1.0, 0.3, 0.2, hand) == (0.0, 0.0, 0.0)
    assert mooring(moor, -0.5, 0.0, 0.0, -1.0, 0.0, 0.0, hand) == (0.0, 0.0, 0.0)


def test_a_taut_line_pulls_towards_the_hand_and_never_pushes():
    moor = _stern_line(line_damping_n_per_mps=15.0)
    hand = mooring_anchor(moor, 0.0, 0.0, 0.0)
    fx, fy, moment = mooring(moor, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, hand)
    assert (fx, fy, moment) == pytest.approx((-300.0 * 0.3, 0.0, 0.0))
    # stretching at 1 m/s adds the hand's damping; shortening fast: slack, not a push
    assert mooring(moor, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, hand)[0] == pytest.approx(-105.0)
    assert mooring(moor, 0.5, 0.0, 0.0, -10.0, 0.0, 0.0, hand) == (0.0, 0.0, 0.0)
    # stern swung to port (yaw -0.1 turns the bow to starboard): the line pulls the stern
    # back to starboard and seaward, a + yaw moment (held astern: stable)
    fx, fy, moment = mooring(moor, 0.3, 0.0, -0.1, 0.0, 0.0, 0.0, hand)
    assert fx < 0.0 and fy < 0.0 and moment > 0.0


def test_mooring_settings_are_checked():
    with pytest.raises(ConfigError, match='mooring.model'):
        dataclasses.replace(PARAMS.mooring, model='chain')
    with pytest.raises(ConfigError):
        dataclasses.replace(PARAMS.mooring, line_slack_m=-0.1)
    with pytest.raises(ConfigError):
        dataclasses.replace(PARAMS.mooring, line_holder_distance_m=0.0)


def _flow(vx: np.ndarray, vy: np.ndarray) -> WaterSample:
    return WaterSample(np.zeros(vx.size), vx, vy, np.zeros(vx.size), np.zeros(vx.size))


@pytest.mark.parametrize('yaw_rad', [0.0, 2.5])
def test_water_yaw_rate_is_the_rotation_of_the_water_over_the_immersed_hull(yaw_rad):
    """Issue 13 (drift): the yaw damping acts on r less the water's rotation over the hulls."""
    xs = np.array([-1.0, 0.0, 1.0, -1.0, 0.0, 1.0])
    ys = np.array([0.4, 0.4, 0.4, -0.4, -0.4, -0.4])
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    ox, oy = c * xs - s * ys, s * xs + c * ys          # odom offsets from the centre
    areas = np.full(6, 0.05)
    spin, drift = 0.2, (0.3, -0.1)                     # rad/s and a uniform current, m/s
    water = _flow(drift[0] - spin * oy, drift[1] + spin * ox)
    assert water_yaw_rate_rps(areas, water, xs, ys, (c, s)) == pytest.approx(spin, rel=1e-12)
    # a uniform flow does not turn the hull; strips out of the water do not count
    assert water_yaw_rate_rps(areas, _flow(np.full(6, 0.3), np.full(6, -0.1)), xs, ys,
                              (c, s)) == pytest.approx(0.0, abs=1e-12)
    shear = _flow(np.zeros(6), np.array([0.0, 0.0, 0.5, 0.0, 0.0, 0.0]))
    bow_dry = areas.copy()
    bow_dry[2] = 0.0
    assert water_yaw_rate_rps(areas, shear, xs, ys, (1.0, 0.0)) > 0.0
    assert water_yaw_rate_rps(bow_dry, shear, xs, ys, (1.0, 0.0)) == 0.0
    assert water_yaw_rate_rps(np.zeros(6), water, xs, ys, (c, s)) == 0.0


@pytest.mark.parametrize('yaw_rad', [0.0, 2.5])
def test_the_water_rotation_weights_each_strips_flow_by_its_drag(yaw_rad):
    """The hulls' drag acts on the cross-flow (sway drag) more than on the along-hull flow
    (surge drag): in an irrotational strain (v = S x, u = S y) the cross-flow turns the hull
    by S, the along-hull flow by -S; weighted equally they give (x^2 - y^2) / (x^2 + y^2) S,
    by the drags' ratio w (x^2 - w y^2) / (x^2 + w y^2) S. A solid-body rotation stays
    what it is at any weighting."""
    xs = np.array([-1.0, 0.0, 1.0, -1.0, 0.0, 1.0])
    ys = np.array([0.4, 0.4, 0.4, -0.4, -0.4, -0.4])
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    areas = np.full(6, 0.05)
    strain = 0.2
    ub, vb = strain * ys, strain * xs                    # body axes
    water = _flow(c * ub - s * vb, s * ub + c * vb)
    x2, y2 = float(np.sum(xs ** 2)), float(np.sum(ys ** 2))
    for w in (1.0, 0.1, 0.0):
        expected = strain * (x2 - w * y2) / (x2 + w * y2)
        assert water_yaw_rate_rps(areas, water, xs, ys, (c, s), surge_to_sway_drag=w) \
            == pytest.approx(expected, rel=1e-12)
    ox, oy = c * xs - s * ys, s * xs + c * ys
    spin = _flow(-0.2 * oy, 0.2 * ox)
    assert water_yaw_rate_rps(areas, spin, xs, ys, (c, s), surge_to_sway_drag=0.1) \
        == pytest.approx(0.2, rel=1e-12)


def test_strip_sums_are_the_area_weighted_sums_strip_by_strip():
    """The one matrix product the wave forces, moments and water yaw rate read."""
    rng = np.random.default_rng(2)
    xs, ys, areas = rng.uniform(-1, 1, 6), rng.uniform(-0.5, 0.5, 6), rng.uniform(0, 0.06, 6)
    kin = rng.normal(size=(4, 9))          # more points than strips: the strips come first
    water = WaterSample(np.zeros(9), *kin)
    sums = strip_sums(areas, water, strip_basis(xs, ys))
    weights = ((1.0, ''), (xs, 'x_'), (ys, 'y_'), (xs ** 2, 'x2_'), (ys ** 2, 'y2_'))
    for weight, prefix in weights:
        for row, name in zip(kin, ('vx', 'vy', 'ax', 'ay'), strict=True):
            want = math.fsum(areas * weight * row[:6])
            assert getattr(sums, prefix + name) == pytest.approx(want, rel=1e-13, abs=1e-15)
    assert sums.area_m2 == pytest.approx(math.fsum(areas), rel=1e-14)
    assert sums.area_x_m3 == pytest.approx(math.fsum(areas * xs), rel=1e-13)
    assert sums.area_y_m3 == pytest.approx(math.fsum(areas * ys), rel=1e-13)
    assert sums.area_x2_m4 == pytest.approx(math.fsum(areas * xs ** 2), rel=1e-13)
    assert sums.area_y2_m4 == pytest.approx(math.fsum(areas * ys ** 2), rel=1e-13)
    # the functions give the same with the caller's sums as with their own, with the drag
    # weighting and the sway inertia coefficient too
    c, s = math.cos(0.7), math.sin(0.7)
    for drag_ratio in (1.0, 0.1):
        assert water_yaw_rate_rps(areas, water, xs, ys, (c, s), drag_ratio, sums) == \
            water_yaw_rate_rps(areas, water, xs, ys, (c, s), drag_ratio)
    args = (False, areas, 0.3, water, PARAMS.waves, 1025.0, xs, ys, (c, s), -0.2)
    for sway_cm in (None, 1.9):
        assert wave_moments(*args, sway_cm, sums) == wave_moments(*args, sway_cm)


def test_the_wave_moments_from_the_sums_are_the_strips_morison_forces():
    """Strip by strip: C_m rho V a along the hull with the surge C_m, across it with the sway
    C_m, at each strip's odom offset; the yaw moment, the body-axes totals (roll, pitch) and
    the transverse force beyond the surge C_m's from the sums are the same."""
    rng = np.random.default_rng(5)
    xs, ys, areas = rng.uniform(-1, 1, 6), rng.uniform(-0.5, 0.5, 6), rng.uniform(0, 0.06, 6)
    water = WaterSample(np.zeros(6), *rng.normal(size=(4, 6)))
    c, s = math.cos(2.1), math.sin(2.1)
    cm_x, cm_y, lever = PARAMS.waves.surge_inertia_coeff, 1.9, -0.2
    rho_v = 1025.0 * areas * 0.3
    ax, ay = water.accel_x_mps2, water.accel_y_mps2
    f_along, f_across = cm_x * rho_v * (c * ax + s * ay), cm_y * rho_v * (-s * ax + c * ay)
    fx, fy = c * f_along - s * f_across, s * f_along + c * f_across       # odom
    yaw = math.fsum((c * xs - s * ys) * fy - (s * xs + c * ys) * fx)
    extra = math.fsum((cm_y - cm_x) / cm_y * f_across)
    got = wave_moments(False, areas, 0.3, water, PARAMS.waves, 1025.0, xs, ys, (c, s), lever,
                       cm_y)
    assert got.yaw_nm == pytest.approx(yaw, rel=1e-12)
    assert got.roll_nm == pytest.approx(-lever * math.fsum(f_across), rel=1e-12)
    assert got.pitch_nm == pytest.approx(lever * math.fsum(f_along), rel=1e-12)
    assert (got.extra_fx_n, got.extra_fy_n) == pytest.approx((-s * extra, c * extra), rel=1e-12)


def test_the_yaw_added_inertia_is_the_one_the_water_turning_over_the_strips_exerts():
    # issue 13 (drift): strip theory's yaw added inertia, sum of a22 x^2, is the added part of
    # the Morison moment the strips feel when the water's cross-flow acceleration grows along
    # the hulls as alpha x (a turning water body), so a free hull turns with the water
    sim = SimCore.from_config()
    sim.reset('afloat')
    x, y = sim.hull.station_x_m, sim.hull.station_y_m
    areas = sim.hull.areas_m2(np.full(x.size, sim.hull.float_depth_m))
    rho = sim.vehicle.body.water_density_kgpm3
    alpha = 0.3                                    # rad/s^2
    zeros = np.zeros(x.size)
    water = WaterSample(zeros, zeros, zeros, -alpha * y, alpha * x)
    ratio = PARAMS.water.sway_added_mass_ratio
    added = (wave_moments(False, areas, sim.hull.strip_length_m, water, PARAMS.waves, rho, x, y,
                          (1.0, 0.0), 0.0, 1.0 + ratio).yaw_nm
             - wave_moments(False, areas, sim.hull.strip_length_m, water, PARAMS.waves, rho, x,
                            y, (1.0, 0.0), 0.0, 1.0).yaw_nm)
    # the transverse part only (the along-hull part, -y ax, is the surge coefficient's)
    strips = strip_yaw_added_inertia_kg_m2(ratio * sim.vehicle.body.mass_kg, x)
    assert added / alpha == pytest.approx(strips, rel=0.03)
    assert strip_yaw_added_inertia_kg_m2(100.0, np.array([-1.0, 1.0])) == pytest.approx(100.0)
    assert strip_yaw_added_inertia_kg_m2(100.0, np.array([-0.5, 0.5])) == pytest.approx(25.0)


def test_the_linear_yaw_damping_grows_with_the_speed_through_the_water():
    # issue 13: under way the hulls' and keels' lift adds a part proportional to the speed
    # (Clarke) to the zero-speed part, either way of the surge
    wat = dataclasses.replace(PARAMS.water, yaw_linear_drag_nm_per_rps=159.0,
                              yaw_lift_damping_nm_s_per_m=700.0)
    assert yaw_linear_drag_nm_per_rps(wat, 0.0) == 159.0
    assert yaw_linear_drag_nm_per_rps(wat, 1.0) == pytest.approx(859.0)
    assert yaw_linear_drag_nm_per_rps(wat, -0.5) == yaw_linear_drag_nm_per_rps(wat, 0.5)
    slow = hydrodynamic_drag(0.0, 0.0, 0.2, 1.0, wat)
    fast = hydrodynamic_drag(1.0, 0.0, 0.2, 1.0, wat)
    assert fast.n_nm < slow.n_nm < 0.0
    # the default: the zero-speed part plus the lift the turns were calibrated with
    assert yaw_linear_drag_nm_per_rps(PARAMS.water, 1.0) == \
        PARAMS.water.yaw_linear_drag_nm_per_rps + PARAMS.water.yaw_lift_damping_nm_s_per_m
