"""The world: beach profile, dispersion, regular and irregular waves, breaking."""
import math

import numpy as np
import pytest

from dukw_common.config import ConfigError
from dukw_sim.core import SimCore
from dukw_sim.world import (Beach, World, cnoidal_factor, cnoidal_second_harmonic,
                            cos2s_density, irregular_waves, jonswap_density, mitsuyasu_exponent,
                            no_waves, regular_waves, spreading_offsets_rad, wavenumber)

SLOPE = math.radians(4.5)


def beach() -> Beach:
    return Beach(SLOPE, 1.5, -8.0)


def test_beach_profile_flat_slope_floor():
    b = beach()
    assert b.height_m(0.0) == 0.0                      # mean waterline at x = 0
    assert b.height_m(-4.0) == pytest.approx(4.0 * math.tan(SLOPE))
    assert b.height_m(-30.0) == pytest.approx(b.sand_height_m)   # flat sand landward
    assert b.height_m(100.0) == pytest.approx(-1.5)    # sea floor
    assert b.gradient(-20.0) == 0.0 and b.gradient(100.0) == 0.0
    assert b.gradient(2.0) == pytest.approx(-math.tan(SLOPE))
    assert b.sea_floor_x_m == pytest.approx(1.5 / math.tan(SLOPE))
    xs = np.array([-30.0, -4.0, 0.0, 5.0, 100.0])
    assert np.allclose(b.heights_m(xs), [b.height_m(x) for x in xs])


@pytest.mark.parametrize('slope, floor, flat', [(0.0, 1.5, -8.0), (0.1, 0.0, -8.0),
                                                (0.1, 1.5, 2.0), (0.7, 1.5, -8.0)])
def test_beach_rejects_bad_geometry(slope, floor, flat):
    with pytest.raises(ValueError):
        Beach(slope, floor, flat)


def test_dispersion_matches_the_papers_wavelength():
    # vehicle.md section 5: 4.88 s waves in 0.76 m depth have a wavelength of about 13 m
    k = wavenumber(2 * math.pi / 4.88, 0.76)
    assert 2 * math.pi / k == pytest.approx(13.0, abs=0.5)
    # deep water limit: omega^2 = g k
    assert wavenumber(2 * math.pi / 2.0, 100.0) == pytest.approx((math.pi) ** 2 / 9.81, rel=1e-6)
    with pytest.raises(ValueError):
        wavenumber(0.0, 1.0)


def test_regular_wave_height_period_and_direction():
    world = World(beach(), regular_waves(0.28, 4.88, 0.76))
    x = 12.0                                   # 0.94 m still depth: not breaking
    t = np.arange(0.0, 4.88, 0.01)
    eta = np.array([world.elevation_m(x, 0.0, ti) for ti in t])
    assert eta.max() - eta.min() == pytest.approx(0.28, rel=0.01)
    # crests travel shoreward (-x) at the phase speed omega / k
    c = (2 * math.pi / 4.88) / wavenumber(2 * math.pi / 4.88, 0.76)
    for t0 in (0.0, 1.0, 2.5):
        assert world.elevation_m(x - c * 0.5, 0.0, t0 + 0.5) == pytest.approx(
            world.elevation_m(x, 0.0, t0), abs=1e-9)
    # under a crest the water moves shoreward (-x), with it
    s = world.sample(np.array([x, x - 1.0, x - 3.0]), np.zeros(3), 0.7, kin_points=3,
                     kin_height_m=-0.3)
    assert np.all(s.velocity_x_mps * s.elevation_m <= 1e-12)
    assert np.any(s.velocity_x_mps != 0.0)


def test_breaking_keeps_the_dry_beach_dry():
    world = World(beach(), regular_waves(0.28, 4.88, 0.76))
    for t in np.arange(0.0, 5.0, 0.25):
        assert world.elevation_m(-2.0, 0.0, t) == 0.0
        assert world.water_depth_m(-2.0, 0.0, t) < 0.0
        # in 0.2 m of water the height is capped at 0.78 x depth
        x = 0.2 / math.tan(SLOPE)
        assert abs(world.elevation_m(x, 0.0, t)) <= 0.5 * 0.78 * 0.2 + 1e-9


def test_irregular_sea_has_the_significant_height_and_is_seeded():
    waves = irregular_waves(0.28, 3.6, 0.76, np.random.default_rng(4), count=24)
    assert 4.0 * math.sqrt(0.5 * np.sum(waves.amplitude_m ** 2)) == pytest.approx(0.28)
    world = World(beach(), waves)
    t = np.arange(0.0, 600.0, 0.1)
    eta = world.sample(np.full(t.size, 20.0), np.zeros(t.size), 0.0).elevation_m  # one instant
    assert eta.size == t.size
    record = np.array([world.elevation_m(20.0, 0.0, ti) for ti in t])
    assert 4.0 * record.std() == pytest.approx(0.28, rel=0.15)
    # the peak of the spectrum near 1 / 3.6 s
    spec = np.abs(np.fft.rfft(record)) ** 2
    freq = np.fft.rfftfreq(record.size, 0.1)
    assert freq[np.argmax(spec)] == pytest.approx(1 / 3.6, abs=0.06)
    again = irregular_waves(0.28, 3.6, 0.76, np.random.default_rng(4), count=24)
    assert np.array_equal(again.phase_rad, waves.phase_rad)
    other = irregular_waves(0.28, 3.6, 0.76, np.random.default_rng(5), count=24)
    assert not np.array_equal(other.phase_rad, waves.phase_rad)


def test_jonswap_integrates_to_the_significant_height():
    f = np.linspace(0.05, 2.0, 4000)
    s = jonswap_density(f, 0.28, 3.6, 3.3)
    assert 4.0 * math.sqrt(np.trapezoid(s, f)) == pytest.approx(0.28, rel=1e-3)
    assert f[np.argmax(s)] == pytest.approx(1 / 3.6, abs=0.005)


def test_calm_water_is_flat():
    world = World(beach(), no_waves())
    assert world.calm
    s = world.sample(np.array([5.0, 10.0]), np.zeros(2), 3.0, kin_points=2)
    assert not np.any(s.elevation_m) and not np.any(s.accel_x_mps2)
    assert world.water_depth_m(10.0, 0.0, 1.0) == pytest.approx(10.0 * math.tan(SLOPE))


def _reference_sample(world: World, x, y, t, kin_height_m):
    """The linear wave field summed component by component (the textbook formulas)."""
    w, beach = world.waves, world.beach
    still = -beach.heights_m(x)
    factor = np.minimum(np.maximum(still, 0.0) * world.breaking_ratio / w.height_scale_m, 1.0)
    depth = max(float(still.mean()), 0.05)
    zc = min(max(kin_height_m, -depth), 0.0)
    eta, vel, acc = np.zeros(x.size), np.zeros((x.size, 2)), np.zeros((x.size, 2))
    for a, om, kx, ky, ph in zip(w.amplitude_m, w.omega_rps, w.kx, w.ky, w.phase_rad,
                                 strict=True):
        k = math.hypot(kx, ky)
        theta = kx * x + ky * y + ph - om * t
        eta += a * np.cos(theta)
        speed = a * om * math.cosh(k * (zc + depth)) / math.sinh(k * depth)
        vel += np.outer(speed * np.cos(theta), [kx / k, ky / k])
        acc += np.outer(speed * om * np.sin(theta), [kx / k, ky / k])
    return factor * eta, factor[:, None] * vel, factor[:, None] * acc


@pytest.mark.parametrize('spread', [{}, {'spreading_exponent_s': 10.0, 'directions': 6}])
def test_vectorised_sample_matches_the_component_sum(spread):
    rng = np.random.default_rng(3)
    world = World(beach(), irregular_waves(0.28, 3.6, 0.76, rng, count=24, **spread))
    x, y = rng.uniform(-3.0, 25.0, 12), rng.uniform(-2.0, 2.0, 12)
    for t in (0.0, 7.31, 250.0):
        s = world.sample(x, y, t, kin_points=12, kin_height_m=-0.25)
        eta, vel, acc = _reference_sample(world, x, y, t, -0.25)
        assert np.allclose(s.elevation_m, eta, rtol=0.0, atol=1e-12)
        assert np.allclose(np.column_stack([s.velocity_x_mps, s.velocity_y_mps]), vel,
                           rtol=0.0, atol=1e-12)
        assert np.allclose(np.column_stack([s.accel_x_mps2, s.accel_y_mps2]), acc,
                           rtol=0.0, atol=1e-12)
    # grids keep their shape (the live scene samples a mesh)
    gx, gy = np.meshgrid(np.linspace(0.0, 20.0, 5), np.linspace(-2.0, 2.0, 3))
    grid = world.sample(gx, gy, 4.0).elevation_m
    assert grid.shape == gx.shape
    assert grid[1, 3] == pytest.approx(world.elevation_m(gx[1, 3], gy[1, 3], 4.0), abs=1e-12)


def test_rigid_body_sample_is_the_sample_at_the_moved_points():
    """sample_rigid (points fixed in a moving body, the simulator's per-step call) gives the
    water of ``sample`` at those points in odom, to round-off, and their odom x."""
    rng = np.random.default_rng(5)
    world = World(beach(), irregular_waves(0.28, 3.6, 0.76, rng, count=24,
                                           spreading_exponent_s=10.0, directions=6))
    bx, by = rng.uniform(-1.5, 1.5, 10), rng.uniform(-0.5, 0.5, 10)
    rows = world.rigid_rows(bx, by, 6)
    full_cap_x = float(world._cap_x[1])        # seaward of this the breaking cap is 1
    poses = ((12.0, 0.3, 2.9, 250.0), (3.0, -1.0, -0.4, 7.31), (-3.0, 0.0, 0.1, 1.0),
             (0.4, 0.0, 1.0, 3.0),                                    # astride the waterline
             (full_cap_x + 0.3, 0.0, 0.2, 9.0), (full_cap_x + 1.7, 0.0, 2.0, 9.0),  # cap's end
             (world.beach.sea_floor_x_m + 1.7, 0.0, 0.5, 2.0),     # over the flat sea floor,
             (world.beach.sea_floor_x_m + 2.0, 0.4, 0.1, 2.5))     # twice (its depth kept)
    for x0, y0, yaw, t in poses:
        c, s = math.cos(yaw), math.sin(yaw)
        px, py = x0 + c * bx - s * by, y0 + s * bx + c * by
        odom_x, rigid = world.sample_rigid(rows, 10, x0, y0, c, s, t, -0.2)
        plain = world.sample(px, py, t, kin_points=6, kin_height_m=-0.2)
        assert np.allclose(odom_x[:10], px, rtol=0.0, atol=1e-13)
        assert np.allclose(odom_x[10:], px[:6], rtol=0.0, atol=1e-13)
        for got, want in zip(rigid, plain, strict=True):
            assert got.shape == want.shape
            assert np.allclose(got, want, rtol=0.0, atol=1e-12)
        assert np.any(rigid.elevation_m != 0.0) == (x0 != -3.0)  # that one: all on the sand
    with pytest.raises(ValueError):
        world.rigid_rows(bx, by, 11)


def test_uniform_spread_sea_is_the_one_of_before_the_spreading_option():
    # waves.spreading_exponent_s = 0 with the uniform 0.35 rad spread (the default until
    # issue 13 made the cos-2s sea the default) keeps the sea of commit da3680a: these
    # elevations were printed by that version's World for the same config and seed
    world = SimCore.from_config(overrides={'waves.model': 'irregular', 'waves.spreading_rad': 0.35,
                                           'waves.spreading_exponent_s': 0.0,
                                           'waves.directions': 1}, seed=1).world
    eta = world.sample(np.array([5.0, 12.0, 20.0]), np.array([0.0, 0.6, -1.0]), 12.5)
    assert eta.elevation_m == pytest.approx(
        [-0.019371501576918866, 0.005617545545349607, 0.12081194374941635], abs=1e-14)


def test_cos2s_spreading_is_normalised_and_has_its_spread():
    theta = np.linspace(-math.pi, math.pi, 20001)
    for s in (1.0, 10.0, 75.0):
        d = cos2s_density(theta, s)
        assert np.trapezoid(d, theta) == pytest.approx(1.0, rel=1e-6)
        assert np.trapezoid(d * np.cos(theta), theta) == pytest.approx(s / (s + 1.0), rel=1e-6)
    offsets = spreading_offsets_rad(10.0, 8)
    assert np.allclose(offsets, -offsets[::-1])                 # symmetric about the mean
    assert np.mean(np.cos(offsets)) == pytest.approx(10.0 / 11.0, abs=0.02)
    assert np.all(np.diff(offsets) > 0.0)
    with pytest.raises(ValueError):
        cos2s_density(theta, 0.0)


def test_short_crested_sea_keeps_hs_and_rocks_the_vehicle_sideways():
    s_exp, directions = 10.0, 6
    spread = irregular_waves(0.28, 3.6, 0.76, np.random.default_rng(4), count=48,
                             spreading_exponent_s=s_exp, directions=directions)
    long_crested = irregular_waves(0.28, 3.6, 0.76, np.random.default_rng(4), count=48)
    energy = spread.amplitude_m ** 2
    heading = np.arctan2(spread.ky, spread.kx)
    # energy-weighted mean direction shoreward, spread as the cos-2s function has it
    mean = math.atan2(np.sum(energy * np.sin(heading)), np.sum(energy * np.cos(heading)))
    assert abs(math.remainder(mean - math.pi, 2 * math.pi)) < 0.1
    cos_moment = np.sum(energy * np.cos(heading - math.pi)) / np.sum(energy)
    assert cos_moment == pytest.approx(s_exp / (s_exp + 1.0), abs=0.05)
    t = np.arange(0.0, 600.0, 0.1)
    half_sep = 0.6                          # the hulls either side of the centreline
    records = {}
    for name, waves in (('spread', spread), ('long', long_crested)):
        world = World(beach(), waves)
        port = np.array([world.elevation_m(20.0, half_sep, ti) for ti in t])
        stbd = np.array([world.elevation_m(20.0, -half_sep, ti) for ti in t])
        records[name] = (port, stbd)
        assert 4.0 * port.std() == pytest.approx(0.28, rel=0.15)     # same Hs either way
        side = [world.sample(np.array([20.0]), np.zeros(1), ti, 1, -0.3).accel_y_mps2[0]
                for ti in t[::10]]
        records[name + '_ay'] = np.std(side)
    port, stbd = records['long']
    assert np.max(np.abs(port - stbd)) < 1e-12          # long-crested: no transverse slope
    assert records['long_ay'] < 1e-12
    port, stbd = records['spread']
    assert np.std(port - stbd) > 0.05 * port.std()      # short-crested: roll and yaw forcing
    assert records['spread_ay'] > 0.05


@pytest.mark.parametrize('overrides', [
    {'waves.spreading_rad': 0.35, 'waves.spreading_exponent_s': 10.0},   # with the uniform
    {'waves.spreading_exponent_s': 10.0, 'waves.directions': 1},          # one direction
    {'waves.spreading_exponent_s': 0.0, 'waves.directions': 4},           # bins, no s
    {'waves.spreading_exponent_s': -1.0},
    {'waves.spreading_exponent_s': 0.0, 'waves.directions': 1, 'waves.spreading_rad': 0.35,
     'waves.spreading_by_frequency': True},                              # s(f) without s_max
])
def test_inconsistent_spreading_settings_are_rejected(overrides):
    with pytest.raises(ConfigError):
        SimCore.from_config(overrides={'waves.model': 'irregular', **overrides})


def test_a_short_crested_sea_is_built_from_the_config():
    sim = SimCore.from_config(overrides={'waves.model': 'irregular', 'waves.spreading_rad': 0.0,
                                         'waves.spreading_exponent_s': 25.0,
                                         'waves.directions': 8}, seed=2)
    waves = sim.world.waves
    heading = np.arctan2(waves.ky, waves.kx)
    assert len(np.unique(np.round(heading, 9))) == 8
    assert waves.height_scale_m == pytest.approx(sim.params.waves.significant_height_m)


def _short_crested_sea():
    return irregular_waves(0.28, 3.6, 0.76, np.random.default_rng(3), count=24,
                           spreading_exponent_s=10.0, directions=6)


def test_second_order_of_a_regular_wave_is_stokes_second_order():
    """Over the flat sea floor (1.5 m, Ursell number ~4: Stokes's range) a regular wave gets
    Stokes's second-order velocity, acceleration and surface (Dean and Dalrymple ch. 11)."""
    height, period, depth, z = 0.2, 3.6, 1.5, -0.3
    waves = regular_waves(height, period, 0.76)
    linear = World(beach(), waves, breaking_ratio=10.0)
    full = World(beach(), waves, breaking_ratio=10.0, second_order='full')
    k, omega, a = float(-waves.kx[0]), float(waves.omega_rps[0]), height / 2.0
    limit = cnoidal_factor(waves.height_scale_m, k, depth)   # the breaking scale's height
    assert 0.98 < limit < 1.0
    u2 = limit * 0.75 * a * a * omega * k * math.cosh(2 * k * (depth + z)) \
        / math.sinh(k * depth) ** 4
    eta2 = limit * k * a * a / 4 * math.cosh(k * depth) * (2 + math.cosh(2 * k * depth)) \
        / math.sinh(k * depth) ** 3
    x = np.full(2, 40.0)                      # over the flat floor, where the depth is 1.5 m
    for t in np.linspace(0.0, period, 7):
        lin = linear.sample(x, np.zeros(2), t, 2, z)
        got = full.sample(x, np.zeros(2), t, 2, z)
        psi = -k * 40.0 - omega * t           # the wave travels towards -x: kx = -k
        # shoreward (-x) velocity and its rate at twice the phase
        assert got.velocity_x_mps[0] - lin.velocity_x_mps[0] == pytest.approx(
            -u2 * math.cos(2 * psi), abs=1e-9)
        assert got.accel_x_mps2[0] - lin.accel_x_mps2[0] == pytest.approx(
            -2 * omega * u2 * math.sin(2 * psi), abs=1e-9)
        assert got.elevation_m[0] - lin.elevation_m[0] == pytest.approx(
            eta2 * math.cos(2 * psi), abs=1e-9)


def test_cnoidal_limit_of_the_second_harmonic():
    """Small Ursell numbers: Stokes's shallow-water second harmonic 3U / (32 pi^2); large ones:
    the cnoidal wave's, rising towards the solitary wave's 1 (never above)."""
    for ursell in (0.1, 1.0):
        assert cnoidal_second_harmonic(ursell) == pytest.approx(
            3 * ursell / (32 * math.pi ** 2), rel=2e-3 * max(ursell, 0.1))
    ratios = [cnoidal_second_harmonic(u) for u in (5.0, 26.0, 48.0, 100.0, 1000.0)]
    assert np.all(np.diff(ratios) > 0.0) and ratios[-1] < 1.0
    assert ratios[2] == pytest.approx(0.378, abs=0.005)     # m = 0.972, nome q = 0.195
    # the factor on Stokes's coefficient: 1 in deep water, < 1 in the shallows
    assert cnoidal_factor(0.28, 0.8, 5.0) == pytest.approx(1.0, abs=1e-3)
    assert 0.7 < cnoidal_factor(0.28, 0.8, 0.73) < 0.95
    assert cnoidal_factor(0.08, 0.8, 0.73) > 0.97             # day 2's sea: nearly Stokes


def test_second_order_acceleration_is_the_rate_of_its_velocity():
    """In a short-crested sea over the slope the second-order acceleration is the time
    derivative of the second-order velocity (both components)."""
    world = World(beach(), _short_crested_sea(), second_order='kinematics')
    x, y, dt = np.array([9.0, 10.0]), np.array([0.3, -0.4]), 1e-4
    for t in (3.0, 17.2, 40.5):
        before = world.sample(x, y, t - dt, 2, -0.35)
        after = world.sample(x, y, t + dt, 2, -0.35)
        now = world.sample(x, y, t, 2, -0.35)
        for vel, acc in (('velocity_x_mps', 'accel_x_mps2'), ('velocity_y_mps', 'accel_y_mps2')):
            rate = (getattr(after, vel) - getattr(before, vel)) / (2 * dt)
            assert np.allclose(getattr(now, acc), rate, atol=1e-5)


def test_second_order_options_change_what_they_name():
    linear = World(beach(), _short_crested_sea())
    kin = World(beach(), _short_crested_sea(), second_order='kinematics')
    full = World(beach(), _short_crested_sea(), second_order='full')
    none = World(beach(), _short_crested_sea(), second_order='none')
    x, y = np.array([8.0, 9.0, 10.0]), np.array([0.4, -0.4, 0.0])
    diffs = {'kin_u': [], 'kin_eta': [], 'full_eta': []}
    for t in np.arange(0.0, 60.0, 0.5):
        lin = linear.sample(x, y, t, 2, -0.35)
        for got, want in zip(none.sample(x, y, t, 2, -0.35), lin, strict=True):
            assert np.array_equal(got, want)                   # 'none': the linear sea
        k, f = kin.sample(x, y, t, 2, -0.35), full.sample(x, y, t, 2, -0.35)
        diffs['kin_u'].append(np.abs(k.velocity_x_mps - lin.velocity_x_mps).max())
        diffs['kin_eta'].append(np.abs(k.elevation_m - lin.elevation_m).max())
        diffs['full_eta'].append(np.abs(f.elevation_m[:2] - lin.elevation_m[:2]).max())
        assert np.array_equal(f.velocity_x_mps, k.velocity_x_mps)
        assert f.elevation_m[2] == lin.elevation_m[2]          # not a kinematic point
    assert max(diffs['kin_eta']) == 0.0
    assert max(diffs['kin_u']) > 0.02 and max(diffs['full_eta']) > 0.005
    with pytest.raises(ValueError):
        World(beach(), _short_crested_sea(), second_order='stokes')


def test_second_order_rigid_sample_is_the_sample_at_the_moved_points():
    world = World(beach(), _short_crested_sea(), second_order='full')
    bx, by = np.array([-1.0, 0.0, 1.0, 0.5]), np.array([0.4, -0.4, 0.4, 0.0])
    rows = world.rigid_rows(bx, by, 3)
    for x0, yaw, t in ((9.3, 3.0, 20.0), (2.0, 0.3, 5.5), (30.0, 1.0, 8.0)):
        c, s = math.cos(yaw), math.sin(yaw)
        _, rigid = world.sample_rigid(rows, 4, x0, 0.0, c, s, t, -0.3)
        plain = world.sample(x0 + c * bx - s * by, s * bx + c * by, t, 3, -0.3)
        for got, want in zip(rigid, plain, strict=True):
            assert np.allclose(got, want, rtol=0.0, atol=1e-12)


def test_second_order_setting_is_checked_and_built_from_the_config():
    with pytest.raises(ConfigError):
        SimCore.from_config(overrides={'waves.model': 'irregular', 'waves.second_order': 'on'})
    sim = SimCore.from_config(overrides={'waves.model': 'irregular',
                                         'waves.second_order': 'kinematics'})
    assert sim.world.second_order


def test_spreading_by_frequency_widens_the_tail_and_keeps_the_rest_of_the_sea():
    assert mitsuyasu_exponent(np.array([0.5, 1.0, 2.0]), 10.0) == pytest.approx(
        [10.0 / 32.0, 10.0, 10.0 * 2.0 ** -2.5])
    kwargs = {'count': 48, 'spreading_exponent_s': 10.0, 'directions': 6}
    fixed = irregular_waves(0.28, 3.6, 0.76, np.random.default_rng(4), **kwargs)
    by_f = irregular_waves(0.28, 3.6, 0.76, np.random.default_rng(4), spreading_by_frequency=True,
                           **kwargs)
    for name in ('amplitude_m', 'omega_rps', 'phase_rad'):   # the same draws
        assert np.array_equal(getattr(fixed, name), getattr(by_f, name))
    assert np.allclose(np.hypot(fixed.kx, fixed.ky), np.hypot(by_f.kx, by_f.ky))
    f_over_peak = by_f.omega_rps / (2.0 * math.pi) * 3.6

    def spread(waves, band):
        offset = np.abs(np.arctan2(waves.ky, -waves.kx))[band]   # from shoreward (pi)
        return float(np.mean(offset))
    near, tail = np.abs(f_over_peak - 1.0) < 0.15, f_over_peak > 1.8
    assert spread(by_f, near) == pytest.approx(spread(fixed, near), rel=0.35)
    assert spread(by_f, tail) > 1.5 * spread(fixed, tail)
