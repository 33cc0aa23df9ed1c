"""Modified Wong traction model (vehicle.md section 6)."""
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from dukw_common.vehicle import SaturatedSandParams, SoilParams
from dukw_model import traction

SOIL = SoilParams(cohesion_pa=150.0, friction_angle_rad=math.radians(9.93), shear_modulus_m=0.053)
L = 1.07
A = 2 * 0.0826 * L


def wong_reference(i, w, soil, area, length):
    """Straight transcription of the paper's formula, for i != 0."""
    k = soil.shear_modulus_m
    bracket = 1 - k / (abs(i) * length) * (1 - math.exp(-abs(i) * length / k))
    return math.copysign(1, i) * (area * soil.cohesion_pa + w * math.tan(
        soil.friction_angle_rad)) * bracket


@pytest.mark.parametrize('i', [-0.9, -0.2, -0.01, 0.003, 0.05, 0.3, 1.0])
def test_matches_the_formula(i):
    got = traction.tractive_force_n(i, 2000.0, SOIL, A, L)
    assert got == pytest.approx(wong_reference(i, 2000.0, SOIL, A, L), rel=1e-9)


def test_zero_slip_gives_zero_force_and_small_slip_is_smooth():
    assert traction.tractive_force_n(0.0, 2000.0, SOIL, A, L) == 0.0
    tiny = traction.tractive_force_n(1e-9, 2000.0, SOIL, A, L)
    assert 0.0 < tiny < 1e-3


def test_sign_follows_slip_and_force_saturates():
    forces = traction.tractive_force_n(np.linspace(-1, 1, 41), 2000.0, SOIL, A, L)
    assert np.all(np.diff(forces) >= 0)
    strength = traction.max_traction_n(2000.0, SOIL, A)
    assert forces[-1] < strength
    assert forces[-1] > 0.9 * strength
    assert forces[0] == pytest.approx(-forces[-1])


def test_zero_shear_modulus_is_the_fully_developed_limit():
    soil = SoilParams(cohesion_pa=180.0, friction_angle_rad=math.radians(5.58), shear_modulus_m=0)
    assert traction.tractive_force_n(0.2, 1000.0, soil, A, L) == pytest.approx(
        traction.max_traction_n(1000.0, soil, A))


def test_no_weight_no_traction():
    assert traction.tractive_force_n(0.5, 0.0, SOIL, A, L) == 0.0


def test_effective_weight_scalar_path_gives_the_array_path_bits():
    """The scalar path (the simulator's every step on the sand) equals the array path to
    the bit, zero weight afloat included."""
    rng = np.random.default_rng(5)
    volumes = np.concatenate([rng.uniform(0.0, 0.4, 200), [0.0, 0.2835, 0.5]])
    slopes = np.concatenate([rng.uniform(0.0, 0.4, 200), [0.0, 0.0785, 0.0785]])
    want = traction.effective_weight_n(2894.0, volumes, slopes, 1025.0, 9.80665)
    got = [traction.effective_weight_n(2894.0, v, a, 1025.0, 9.80665)
           for v, a in zip(volumes.tolist(), slopes.tolist(), strict=True)]
    assert _bits(got) == _bits(want)
    assert got[-1] == 0.0 and got[-3] > 0.0


def test_effective_weight_goes_to_zero_afloat_and_scales_with_cos_slope():
    assert traction.effective_weight_n(2894.0, 0.0, 0.0, 1025, 9.81) == 2894.0
    assert traction.effective_weight_n(2894.0, 0.0, math.radians(11), 1025, 9.81) == \
        pytest.approx(2894.0 * math.cos(math.radians(11)))
    assert traction.effective_weight_n(2894.0, 0.5, 0.0, 1025, 9.81) == 0.0


def test_slip_definition_and_guard_near_standstill():
    assert traction.slip(2.0, 1.5) == pytest.approx(0.25)
    assert traction.slip(1.0, 1.2) == pytest.approx(-0.2)  # waves push the vehicle
    assert traction.slip(0.0, 0.0) == 0.0
    assert traction.slip(0.0, 0.5) == -1.0
    assert traction.slip(-1.0, -0.5) == pytest.approx(0.5)


@given(st.floats(-1e3, 1e3, allow_nan=False), st.floats(-1e3, 1e3, allow_nan=False))
def test_slip_is_always_finite_and_bounded(vt, vr):
    i = traction.slip(vt, vr)
    assert -1.0 <= i <= 1.0


@given(st.floats(-1, 1), st.floats(0, 5000), st.floats(0, 0.3))
def test_force_never_exceeds_strength(i, w, k):
    soil = SoilParams(150.0, 0.2, k)
    force = traction.tractive_force_n(i, w, soil, A, L)
    assert math.isfinite(force)
    assert abs(force) <= traction.max_traction_n(w, soil, A) + 1e-9


def test_track_force_on_the_vehicle_follows_the_belt_against_the_ground():
    """Forward drive pushes forward, reverse drive backward; a stopped track brakes a vehicle
    rolling either way (the model's force is signed like the slip, relative to the track)."""
    w, a, l_m = 1400.0, 0.088, 1.07
    forward = traction.track_force_n(1.0, 0.8, w, SOIL, a, l_m)
    reverse = traction.track_force_n(-1.0, -0.8, w, SOIL, a, l_m)
    assert forward > 0.0 and reverse == pytest.approx(-forward)
    assert traction.track_force_n(0.0, 0.5, w, SOIL, a, l_m) < 0.0      # braking, rolling on
    assert traction.track_force_n(0.0, -0.5, w, SOIL, a, l_m) > 0.0     # braking, rolling back
    vec = traction.track_force_n(np.array([1.0, -1.0]), np.array([0.8, -0.8]), w, SOIL, a, l_m)
    assert vec.tolist() == pytest.approx([forward, -forward])


def test_the_scalar_path_gives_the_array_path_bit_for_bit():
    """The simulator and the EKF call these per track and per step with floats: the fast
    scalar path must give exactly the vectorised result, signed zeros included."""
    import math

    import numpy as np

    from dukw_common.vehicle import SoilParams
    from dukw_model import traction as tr
    soil = SoilParams(1200.0, 0.55, 0.04)
    rng = np.random.default_rng(3)
    speeds = rng.normal(0.0, 1.0, (4000, 2))
    speeds[::10, 0] = 0.0                              # stopped tracks
    for v_t, v_r in speeds:
        i = tr.slip(v_t, v_r)
        assert i == tr.slip(np.array([v_t]), np.array([v_r]))[0]
        for slip_ in (i, 0.0, -0.0):
            w = rng.normal(500.0, 800.0)               # some without weight (afloat)
            one = tr.tractive_force_n(slip_, w, soil, 0.5, 1.2)
            many = tr.tractive_force_n(np.array([slip_]), np.array([w]), soil, 0.5, 1.2)[0]
            assert one == many and math.copysign(1.0, one) == math.copysign(1.0, many)


# ------------------------------------------------ pore suction of saturated sand (issue 13)
SUCTION = SaturatedSandParams(suction_ratio_per_mps=2.0, max_pore_suction_pa=100000.0)


def test_pore_suction_grows_with_slip_velocity_pressure_and_saturation_up_to_cavitation():
    p = 10000.0                                                         # contact pressure, Pa
    assert traction.pore_suction_pa(0.0, p, 1.0, SUCTION) == 0.0        # no shearing
    assert traction.pore_suction_pa(1.0, p, 0.0, SUCTION) == 0.0        # dry sand
    assert traction.pore_suction_pa(1.0, 0.0, 1.0, SUCTION) == 0.0      # not pressed in
    assert traction.pore_suction_pa(-0.5, p, 1.0, SUCTION) == pytest.approx(10000.0)
    assert traction.pore_suction_pa(0.5, p, 0.5, SUCTION) == pytest.approx(5000.0)
    assert traction.pore_suction_pa(0.5, 2 * p, 1.0, SUCTION) == pytest.approx(20000.0)
    assert traction.pore_suction_pa(50.0, p, 1.0, SUCTION) == pytest.approx(100000.0)
    arr = traction.pore_suction_pa(np.array([0.0, 1.0, 9.0]), p, 1.0, SUCTION)
    assert arr == pytest.approx([0.0, 20000.0, 100000.0])
    with pytest.raises(ValueError):
        SaturatedSandParams(-1.0, 0.0)


def test_dry_or_unsheared_sand_gives_the_plain_wong_force():
    for v_t, v_r in ((1.2, 0.8), (0.5, 0.5), (-1.0, -0.4)):
        plain = traction.track_force_n(v_t, v_r, 1000.0, SOIL, A / 2, L)
        dry = traction.track_force_n(v_t, v_r, 1000.0, SOIL, A / 2, L, SUCTION, 0.0)
        assert dry == plain
    afloat = traction.track_force_n(1.2, 0.2, 0.0, SOIL, A / 2, L, SUCTION, 1.0)
    assert afloat == 0.0                                   # off the ground: no patch at all


def test_saturated_sand_strengthens_with_slip_velocity_within_the_cavitation_bound():
    speeds = (0.4, 0.8, 1.2, 2.0)
    forces = [traction.track_force_n(v_t, 0.2, 1000.0, SOIL, A / 2, L, SUCTION, 1.0)
              for v_t in speeds]
    plain = [traction.track_force_n(v_t, 0.2, 1000.0, SOIL, A / 2, L) for v_t in speeds]
    assert all(f > p for f, p in zip(forces, plain, strict=True))
    assert forces == sorted(forces)
    # at slip velocity 1.0 m/s the suction is 2 x the contact pressure: the normal force x 3
    gain = forces[2] / plain[2]
    expected = (A / 2 * SOIL.cohesion_pa + 3.0 * 1000.0
                * math.tan(SOIL.friction_angle_rad)) / (
        A / 2 * SOIL.cohesion_pa + 1000.0 * math.tan(SOIL.friction_angle_rad))
    assert gain == pytest.approx(expected, rel=1e-9)
    bound = traction.max_traction_n(1000.0, SOIL, A / 2, SUCTION.max_pore_suction_pa)
    assert traction.track_force_n(50.0, 0.0, 1000.0, SOIL, A / 2, L, SUCTION, 1.0) <= bound
    braking = traction.track_force_n(0.2, 1.2, 1000.0, SOIL, A / 2, L, SUCTION, 1.0)
    assert braking < traction.track_force_n(0.2, 1.2, 1000.0, SOIL, A / 2, L) < 0.0


def test_saturated_share_of_a_patch_on_a_plane_beach():
    # depth over the sand d0 + g x along a 1 m patch: wet where it is > 0
    assert traction.saturated_share(0.0, 0.1, 1.0) == pytest.approx(0.5)
    assert traction.saturated_share(0.0, -0.1, 1.0) == pytest.approx(0.5)
    assert traction.saturated_share(0.025, 0.1, 1.0) == pytest.approx(0.75)
    assert traction.saturated_share(-1.0, 0.1, 1.0) == 0.0
    assert traction.saturated_share(1.0, 0.1, 1.0) == 1.0
    assert traction.saturated_share(0.01, 0.0, 1.0) == 1.0         # level water over the patch
    assert traction.saturated_share(-0.01, 0.0, 1.0) == 0.0


def _bits(values) -> list:
    """Floats as their bit patterns (signed zeros differ)."""
    return [float(v).hex() + ('-' if math.copysign(1.0, v) < 0 else '+') for v in values]


@pytest.mark.parametrize('weight_n, saturation, soil', [
    (1200.0, 0.0, SOIL), (1200.0, 0.6, SOIL), (1200.0, 1.0, SOIL), (0.0, 0.5, SOIL),
    (800.0, 0.8, SoilParams(0.0, math.radians(31.0), 0.0))])
def test_float_path_gives_the_array_path_bits(weight_n, saturation, soil):
    """track_force_f / slip_f (the simulator's per-track calls) equal track_force_n / slip
    of arrays to the bit, signed zeros included, with and without the pore suction."""
    suction = SaturatedSandParams(suction_ratio_per_mps=0.9, max_pore_suction_pa=9000.0)
    rng = np.random.default_rng(7)
    speeds = np.concatenate([rng.uniform(-2.0, 2.0, 400), [0.0, -0.0, 0.01, -0.01, 0.3, -0.3]])
    grounds = np.concatenate([rng.uniform(-2.0, 2.0, 400), [0.0, 0.0, 0.01, -0.01, 0.0, 0.0]])
    grounds[:50] = speeds[:50]                                    # no slip
    grounds[50:100] = speeds[50:100] + rng.normal(0.0, 1e-4, 50)  # nearly none
    want = traction.track_force_n(speeds, grounds, weight_n, soil, A / 2, L, suction,
                                  saturation)
    patch = traction.TrackPatch(weight_n, soil, A / 2, L, suction, saturation)
    pairs = list(zip(speeds.tolist(), grounds.tolist(), strict=True))
    got = [traction.track_force_f(patch, v, g) for v, g in pairs]
    assert _bits(got) == _bits(want)
    slips = [traction.slip_f(v, g) for v, g in pairs]
    assert _bits(slips) == _bits(traction.slip(speeds, grounds))
    assert patch.strength_n(450.0) == traction.max_traction_n(weight_n, soil, A / 2, 450.0)


@pytest.mark.parametrize('weight_n, saturation, soil', [
    (1200.0, 0.0, SOIL), (1200.0, 0.6, SOIL), (0.0, 0.5, SOIL),
    (800.0, 0.8, SoilParams(0.0, math.radians(31.0), 0.0))])
def test_force_slopes_give_the_force_bits_and_its_derivatives(weight_n, saturation, soil):
    """track_force_slopes_f: the force of track_force_f to the bit, and derivatives in the
    track and the ground speed that match central differences (away from the kinks: the
    reversing track at v = 0, the held slip denominator at |v| = 0.05, the clip at |i| = 1,
    the suction's cap; with no shear modulus the force steps at i = 0)."""
    suction = SaturatedSandParams(suction_ratio_per_mps=0.9, max_pore_suction_pa=9000.0)
    patch = traction.TrackPatch(weight_n, soil, A / 2, L, suction, saturation)
    rng = np.random.default_rng(11)
    speeds = np.concatenate([rng.uniform(-2.0, 2.0, 300), [0.0, -0.0, 0.03, -0.03, 0.8]])
    grounds = np.concatenate([speeds[:300] + rng.normal(0.0, 0.3, 300), [0.0, 0.0, 0.0, 0.0,
                                                                         0.8]])
    step = 1e-6
    checked = 0
    for v, g in zip(speeds.tolist(), grounds.tolist(), strict=True):
        force, d_track, d_ground = traction.track_force_slopes_f(patch, v, g)
        assert _bits([force]) == _bits([traction.track_force_f(patch, v, g)])
        i = traction.slip_f(v, g)
        step_at_zero = abs(i) if soil.shear_modulus_m <= 1e-9 else 1.0
        far = min(abs(v), abs(abs(v) - 0.05), 1.0 - abs(i), step_at_zero, abs(abs(v - g)
                  - 9000.0 / 0.9 / (patch.pressure_pa or 1.0))) > 1e-3
        if not far:
            continue
        f = traction.track_force_f
        want_t = (f(patch, v + step, g) - f(patch, v - step, g)) / (2 * step)
        want_g = (f(patch, v, g + step) - f(patch, v, g - step)) / (2 * step)
        assert d_track == pytest.approx(want_t, rel=1e-4, abs=1e-2)
        assert d_ground == pytest.approx(want_g, rel=1e-4, abs=1e-2)
        checked += 1
    assert checked > 200
    if weight_n > 0.0 and soil.shear_modulus_m > 0.0:   # more track speed, more force
        assert traction.track_force_slopes_f(patch, 0.8, 0.8)[1] > 0.0
