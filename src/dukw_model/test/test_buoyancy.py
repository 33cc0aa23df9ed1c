"""Hull submersion model (vehicle.md section 6) against independent numeric integration."""
import math

import numpy as np
import pytest
from scipy.integrate import quad

from dukw_model import buoyancy

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


SECTION = buoyancy.HullSection.of_hulls(0.2878, R, 2.54, 0.89)


@pytest.mark.parametrize('depth', [0.0, 0.03, 0.14, 0.2, 0.28, 0.5])
def test_segment_area_integral_matches_quadrature(depth):
    expected = quad(lambda u: float(buoyancy.segment_area_m2(u, R)), 0.0, depth,
                    epsabs=1e-15, epsrel=1e-12)[0]
    assert buoyancy.segment_area_integral_m3_per_m(depth, R) == pytest.approx(
        expected, rel=1e-9, abs=1e-15)


def test_hull_section_floats_the_displacement_and_goes_wall_sided_above():
    two_hulls = 2 * SECTION.area_m2(SECTION.float_depth_m) * 2.54
    assert two_hulls == pytest.approx(0.2878, rel=1e-9)
    above = SECTION.area_m2(SECTION.float_depth_m + 0.1) - SECTION.area_m2(SECTION.float_depth_m)
    assert above == pytest.approx(0.1 * 0.89 / (2 * 2.54), rel=1e-9)   # the strut's waterplane
    assert SECTION.area_m2(-0.1) == 0.0


@pytest.mark.parametrize('depth0, gradient', [(0.2, 0.05), (0.3, -0.1), (0.45, 0.0),
                                              (0.1, 0.3), (-0.05, 0.08), (0.6, -0.02)])
def test_line_volume_is_the_section_integrated_along_the_hull(depth0, gradient):
    expected = quad(lambda x: float(SECTION.area_m2(depth0 + gradient * x)), -1.27, 1.27,
                    points=[0.0], epsabs=1e-15, epsrel=1e-12, limit=200)[0]
    got = SECTION.line_volume_m3(depth0, gradient, 1.27, -1.27)
    assert got == pytest.approx(expected, rel=1e-6, abs=1e-12)


def test_grounded_volume_with_struts_exceeds_the_bare_cylinders_only_above_the_float_line():
    args = (SLOPE, 0.25, 1.27, -1.27, R)
    shallow = buoyancy.grounded_volume_m3(2.0, *args)
    assert buoyancy.grounded_volume_m3(2.0, *args, section=SECTION) == pytest.approx(shallow)
    deep_cylinders = buoyancy.grounded_volume_m3(12.0, *args)
    assert deep_cylinders == pytest.approx(2 * math.pi * R * R * 2.54)    # the cylinders, full
    assert buoyancy.grounded_volume_m3(12.0, *args, section=SECTION) > 1.2 * deep_cylinders


DECKED = buoyancy.HullSection.of_hulls(0.2878, R, 2.54, 0.89, top_depth_m=0.36)


def test_water_over_the_deck_displaces_nothing_more():
    top = DECKED.area_m2(0.36)
    assert DECKED.area_m2(0.5) == top == DECKED.max_area_m2()
    assert DECKED.area_m2(0.3) == SECTION.area_m2(0.3)
    assert DECKED.area_integral_m3_per_m(0.6) == pytest.approx(
        DECKED.area_integral_m3_per_m(0.36) + 0.24 * top)
    assert buoyancy.HullSection(R, 2 * R, 0.0).max_area_m2() == pytest.approx(math.pi * R * R)
    assert SECTION.max_area_m2() == math.inf


@pytest.mark.parametrize('depth0, gradient', [(0.3, 0.1), (0.5, -0.05), (0.2, 0.3)])
def test_decked_line_volume_is_the_section_integrated(depth0, gradient):
    expected = quad(lambda x: float(DECKED.area_m2(depth0 + gradient * x)), -1.27, 1.27,
                    epsabs=1e-15, epsrel=1e-12, limit=200)[0]
    assert DECKED.line_volume_m3(depth0, gradient, 1.27, -1.27) == pytest.approx(
        expected, rel=1e-6)


@pytest.mark.parametrize('s', [2.0, 3.0, 3.5, 4.0])
def test_grounded_volume_is_the_papers_formula_while_the_stern_is_dry(s):
    """The section's line integral (bare cylinder) against the paper's closed form of h2."""
    args = (s, SLOPE, 0.25, 1.27, -1.27)
    h2 = buoyancy.submerged_length_m(*args)
    assert 0.0 < h2 < 2.54                               # bow wet, stern dry
    expected = 2.0 * buoyancy.hull_volume_on_slope(h2, SLOPE, R)
    assert buoyancy.grounded_volume_m3(*args, R) == pytest.approx(expected, rel=1e-9)


def test_the_scalar_section_gives_the_array_section_bit_for_bit():
    """Per-strip and per-hull calls take floats: the scalar path must match the array path."""
    import numpy as np

    from dukw_model.buoyancy import HullSection, segment_area_m2
    section = HullSection(0.3, 0.45, 0.2, 0.9)
    edges = [0.0, -0.0, 0.6, 0.45, 0.9, 1e-300, 0.6 - 1e-16]   # clip and section limits
    for depth in [*edges, *np.random.default_rng(5).uniform(-0.2, 1.2, 5000)]:
        assert segment_area_m2(float(depth), 0.3) == segment_area_m2(np.array([depth]), 0.3)[0]
        assert section.area_m2(float(depth)) == section.area_m2(np.array([depth]))[0]
    # the array path folds the clips: a float line at the top of the circle, and none
    for other in (HullSection(0.3, 0.6, 0.2), HullSection(0.3, 0.0, 0.1, 0.5)):
        depths = np.array([*edges, *np.random.default_rng(6).uniform(-0.2, 1.2, 2000)])
        assert [other.area_m2(float(d)) for d in depths] == other.area_array_m2(depths).tolist()


def test_the_deepest_depth_hint_skips_only_what_adds_nothing():
    """area_array_m2 with the caller's max depth: the same bits, the input left as it was."""
    import numpy as np

    from dukw_model.buoyancy import HullSection
    rng = np.random.default_rng(7)
    for section in (HullSection(0.3, 0.45, 0.2, 0.9), HullSection(0.3, 0.6, 0.2),
                    HullSection(0.3, 0.0, 0.1, 0.5)):
        for lo, hi in ((-0.2, 0.44), (-0.2, 0.85), (0.1, 1.2), (0.0, 0.0)):
            depths = rng.uniform(lo, hi, 16)
            kept = depths.copy()
            hinted = section.area_array_m2(depths, float(depths.max()))
            assert np.array_equal(depths, kept)
            assert hinted.tolist() == section.area_array_m2(depths.copy()).tolist()
            assert hinted.tolist() == [section.area_m2(float(d)) for d in depths]
