"""Hull submersion model (vehicle.md section 6) against independent numeric integration."""
import math

import numpy as np
import pytest
from scipy.integrate import quad

from dukw_estimation import buoyancy

R = 0.14
SLOPE = math.radians(4.5)


def paper_integral(h2, slope, r):
    """The paper's two cases, the integral done numerically (independent of the closed form)."""
    if h2 < 2 * r / math.tan(slope):
        beta = h2 * math.tan(slope)
        return 2 * quad(lambda xi: h2 * (xi - r + beta) / beta * math.sqrt(r * r - xi * xi),
                        r - beta, r, epsabs=1e-15, epsrel=1e-12)[0]
    return (h2 - r / math.tan(slope)) * math.pi * r * r


@pytest.mark.parametrize('h2', [0.01, 0.2, 1.0, 2.5, 3.55, 3.56, 5.0])
@pytest.mark.parametrize('slope_deg', [3.0, 4.5, 6.0, 11.0])
def test_closed_form_matches_the_integral_to_1e6(h2, slope_deg):
    slope = math.radians(slope_deg)
    expected = paper_integral(h2, slope, R)
    got = buoyancy.hull_volume_on_slope(h2, slope, R)
    assert got == pytest.approx(expected, rel=1e-6, abs=1e-12)


def test_continuous_where_the_hull_tops_go_under():
    edge = 2 * R / math.tan(SLOPE)
    below = buoyancy.hull_volume_on_slope(edge * (1 - 1e-9), SLOPE, R)
    above = buoyancy.hull_volume_on_slope(edge * (1 + 1e-9), SLOPE, R)
    assert below == pytest.approx(above, rel=1e-6)


def test_vectorised_and_monotonic_and_capped_at_the_whole_hull():
    h2 = np.linspace(0.0, 20.0, 400)
    vol = buoyancy.hull_volume_on_slope(h2, SLOPE, R, length_m=2.54)
    assert vol.shape == h2.shape
    assert vol[0] == 0.0
    assert np.all(np.diff(vol) >= -1e-15)
    assert vol[-1] == pytest.approx(math.pi * R * R * 2.54)
    both = buoyancy.submerged_volume_on_slope(h2, SLOPE, R, 2.54)
    np.testing.assert_allclose(both, 2 * vol)


def test_general_strip_form_agrees_with_the_paper_form_on_a_slope():
    for h2 in [0.3, 1.7, 3.0, 4.2]:
        n = 2000
        stations = (np.arange(n) + 0.5) / n * h2
        depths = (h2 - stations) * math.tan(SLOPE)
        strip = buoyancy.hull_volume_from_depths(depths, R, h2)
        assert strip == pytest.approx(buoyancy.hull_volume_on_slope(h2, SLOPE, R), rel=1e-4)


def test_segment_area_limits():
    assert buoyancy.segment_area_m2(0.0, R) == 0.0
    assert buoyancy.segment_area_m2(R, R) == pytest.approx(math.pi * R * R / 2)
    assert buoyancy.segment_area_m2(5.0, R) == pytest.approx(math.pi * R * R)


def test_slope_must_be_positive():
    with pytest.raises(ValueError):
        buoyancy.hull_volume_on_slope(1.0, 0.0, R)


def test_afloat_volume_is_the_displacement():
    assert buoyancy.afloat_volume_m3(2894.0, 1025.0, 9.81) == pytest.approx(0.2878, abs=1e-4)
