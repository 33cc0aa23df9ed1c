"""The world: beach profile, dispersion, regular and irregular waves, breaking."""
import math

import numpy as np
import pytest

from dukw_sim.world import (Beach, World, irregular_waves, jonswap_density, no_waves,
                            regular_waves, wavenumber)

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
