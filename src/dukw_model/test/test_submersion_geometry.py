"""h2 and the grounded hull volume from the waterline distance (buoyancy.py additions)."""
import math

import numpy as np
import pytest

from dukw_model import buoyancy

R, CLEAR, BOW, STERN = 0.14, 0.25, 1.245, -1.295
SLOPE = math.radians(4.5)
LENGTH = BOW - STERN


def strip_volume(s, slope, surface=0.0, heading_cos=1.0, n=4000):
    """Both hulls by strips: water depth normal to the hull over each station's bottom."""
    x = STERN + (np.arange(n) + 0.5) / n * LENGTH
    bottom_z = -(s + x * heading_cos) * math.sin(slope) + CLEAR * math.cos(slope)
    depths = (surface - bottom_z) / math.cos(slope)
    return 2 * buoyancy.hull_volume_from_depths(depths, R, LENGTH)


def test_h2_is_zero_up_the_beach_full_length_deep_and_linear_between():
    entry = CLEAR / math.tan(SLOPE)          # waterline distance where the bottom line gets wet
    assert buoyancy.submerged_length_m(-3.0, SLOPE, CLEAR, BOW, STERN) == 0.0
    assert buoyancy.submerged_length_m(entry - BOW + 0.5, SLOPE, CLEAR, BOW, STERN) == \
        pytest.approx(0.5, rel=1e-6)
    assert buoyancy.submerged_length_m(30.0, SLOPE, CLEAR, BOW, STERN) == pytest.approx(LENGTH)


def test_h2_stern_first_mirrors_bow_first():
    bow_first = buoyancy.submerged_length_m(3.6, SLOPE, CLEAR, BOW, -BOW)
    stern_first = buoyancy.submerged_length_m(3.6, SLOPE, CLEAR, BOW, -BOW, heading_cos=-1.0)
    assert stern_first == pytest.approx(bow_first)


def test_a_wave_crest_acts_like_moving_seaward():
    rise = 0.1
    assert buoyancy.submerged_length_m(3.0, SLOPE, CLEAR, BOW, STERN, surface_m=rise) == \
        pytest.approx(buoyancy.submerged_length_m(3.0 + rise / math.sin(SLOPE), SLOPE, CLEAR,
                                                  BOW, STERN))


@pytest.mark.parametrize('s', [2.0, 3.5, 5.0, 6.5, 9.0])
@pytest.mark.parametrize('heading_cos', [1.0, -1.0, 0.5])
def test_grounded_volume_matches_strip_integration(s, heading_cos):
    got = buoyancy.grounded_volume_m3(s, SLOPE, CLEAR, BOW, STERN, R, heading_cos=heading_cos)
    assert got == pytest.approx(strip_volume(s, SLOPE, heading_cos=heading_cos), rel=2e-3,
                                abs=1e-6)


def test_grounded_volume_is_the_paper_form_while_the_stern_is_dry():
    s = 4.0
    h2 = buoyancy.submerged_length_m(s, SLOPE, CLEAR, BOW, STERN)
    assert 0.0 < h2 < LENGTH
    assert buoyancy.grounded_volume_m3(s, SLOPE, CLEAR, BOW, STERN, R) == pytest.approx(
        buoyancy.submerged_volume_on_slope(h2, SLOPE, R))


def test_flat_bottom_uses_uniform_depth():
    got = buoyancy.grounded_volume_m3(0.0, 0.0, CLEAR, BOW, STERN, R, surface_m=CLEAR + R)
    assert got == pytest.approx(math.pi * R * R * LENGTH)      # half of each hull, two hulls
    assert buoyancy.grounded_volume_m3(-5.0, 0.0, CLEAR, BOW, STERN, R) == 0.0
