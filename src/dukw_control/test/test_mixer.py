"""Mixers: skid-steer kinematics, thrust model, yaw priority, 44/100 limit, port bias."""
import math

import pytest

from dukw_control.mixer import (LandMixer, SidePair, WaterMixer, apply_port_bias,
                                saturate_yaw_priority)

LAND = LandMixer(full_scale_track_speed_mps=2.0, effective_track_separation_m=1.6,
                 max_differential_ratio=0.44)
WATER = WaterMixer(max_thrust_n=133.0, reverse_thrust_ratio=0.6, thrust_exponent=1.0,
                   prop_arm_m=0.405, max_speed_mps=1.2, yaw_rate_at_full_moment_rps=0.35)


def test_land_straight_is_track_speed_over_full_scale():
    mix = LAND.mix(1.0, 0.0)
    assert mix.sides == SidePair(50.0, 50.0)
    assert not mix.speed_saturated and not mix.yaw_saturated


def test_land_left_turn_runs_starboard_faster_by_the_effective_separation():
    mix = LAND.mix(1.0, 0.2)         # d = 0.2 * 0.8 m / 2 m/s * 100 = 8 %
    assert mix.sides.port == pytest.approx(42.0)
    assert mix.sides.stbd == pytest.approx(58.0)
    assert LAND.yaw_rate_of(mix.sides) == pytest.approx(0.2)


def test_land_differential_never_beyond_44_over_100():
    for v, w in ((1.0, 1.5), (0.3, -1.0), (-1.0, 1.0), (2.0, 1.5)):
        sides = LAND.mix(v, w).sides
        slow, fast = sorted((abs(sides.port), abs(sides.stbd)))
        assert slow / fast >= 0.44 - 1e-9
        assert sides.port * sides.stbd >= 0.0            # never counter-rotating on land
    assert LAND.mix(0.0, 0.5).sides == SidePair(0.0, 0.0)   # no pivot turn on land
    assert LAND.mix(1.0, 1.5).yaw_saturated


def test_yaw_priority_gives_up_speed_first():
    c, d, speed_sat, yaw_sat = saturate_yaw_priority(100.0, 20.0, -100.0, 100.0)
    assert (c, d) == (80.0, 20.0) and speed_sat and not yaw_sat
    c, d, speed_sat, yaw_sat = saturate_yaw_priority(50.0, 150.0, -100.0, 100.0)
    assert (c, d) == (0.0, 100.0) and yaw_sat
    sides = LAND.mix(2.0, 0.4).sides        # both saturating: the difference is kept
    assert max(sides.port, sides.stbd) == pytest.approx(100.0)
    assert sides.stbd - sides.port == pytest.approx(0.4 * 0.8 / 2.0 * 100 * 2)


def test_water_full_speed_is_full_thrust_and_inverse_is_consistent():
    assert WATER.mix(1.2, 0.0).sides == SidePair(100.0, 100.0)
    half = WATER.mix(1.2 / math.sqrt(2), 0.0).sides
    assert half.port == pytest.approx(50.0)
    for pct in (-100, -30, 0, 20, 100):
        assert WATER.thrust_to_pct(WATER.pct_to_thrust(pct)) == pytest.approx(pct)
    assert WATER.pct_to_thrust(-100) == pytest.approx(-133.0 * 0.6)


def test_water_turn_on_the_spot_reverses_one_propeller_within_its_weaker_limit():
    sides = WATER.mix(0.0, 0.35).sides      # full moment: one ahead, one astern
    assert sides.stbd > 0 > sides.port
    assert WATER.pct_to_thrust(sides.stbd) - WATER.pct_to_thrust(sides.port) == \
        pytest.approx(133.0 * 1.6)
    assert abs(sides.port) <= 100.0 and abs(sides.stbd) <= 100.0


def test_port_bias_makes_60_56_and_keeps_neutral_neutral():
    assert apply_port_bias(SidePair(56.0, 56.0), 4.0, 10.0) == SidePair(60.0, 56.0)
    assert apply_port_bias(SidePair(0.0, 0.0), 4.0, 10.0) == SidePair(0.0, 0.0)
    assert apply_port_bias(SidePair(5.0, 5.0), 4.0, 10.0).port == pytest.approx(7.0)
    assert apply_port_bias(SidePair(-56.0, -56.0), 4.0, 10.0) == SidePair(-60.0, -56.0)
    assert apply_port_bias(SidePair(100.0, 100.0), 4.0, 10.0) == SidePair(100.0, 96.0)


def test_bad_mixer_settings_are_refused():
    with pytest.raises(ValueError):
        LandMixer(2.0, 0.0, 0.44)
    with pytest.raises(ValueError):
        WaterMixer(133.0, 0.6, 1.0, 0.405, 0.0, 0.35)
