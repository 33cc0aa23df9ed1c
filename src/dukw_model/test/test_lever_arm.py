"""Lever arms: forward and back are inverses, and the offset is R (0, 0, h)."""
import math

import numpy as np
import pytest

from dukw_model.lever_arm import (base_from_sensor_point, lever_arm_enu,
                                  sensor_point_enu, sensor_point_velocity_body,
                                  specific_force_at_base, specific_force_at_sensor)

RNG = np.random.default_rng(7)
POSES = [(tuple(RNG.uniform(-30, 30, 3)), *RNG.uniform(-0.6, 0.6, 2), RNG.uniform(-3.2, 3.2))
         for _ in range(50)]


def rotation(roll, pitch, yaw):
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch),
                              math.sin(pitch), math.cos(yaw), math.sin(yaw))
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    return rz @ ry @ rx


@pytest.mark.parametrize('base,roll,pitch,yaw', POSES)
def test_position_round_trip(base, roll, pitch, yaw):
    sensor = sensor_point_enu(base, roll, pitch, yaw, 1.0)
    assert base_from_sensor_point(sensor, roll, pitch, yaw, 1.0) == pytest.approx(base, abs=1e-12)
    assert np.linalg.norm(np.subtract(sensor, base)) == pytest.approx(1.0)


@pytest.mark.parametrize('base,roll,pitch,yaw', POSES[:10])
def test_offset_is_the_rotated_mast(base, roll, pitch, yaw):
    want = rotation(roll, pitch, yaw) @ np.array([0.0, 0.0, 0.7])
    assert lever_arm_enu(roll, pitch, yaw, 0.7) == pytest.approx(tuple(want), abs=1e-12)


def test_level_vehicle_has_the_sensor_straight_above():
    assert sensor_point_enu((1.0, 2.0, 0.3), 0.0, 0.0, 1.2, 0.5) == pytest.approx((1.0, 2.0, 0.8))
    # nose down (positive pitch) moves the mast head forward: +x at yaw 0
    assert lever_arm_enu(0.0, 0.1, 0.0, 1.0)[0] > 0.0
    # starboard down (positive roll) moves it to -y
    assert lever_arm_enu(0.1, 0.0, 0.0, 1.0)[1] < 0.0


def test_specific_force_round_trip_and_centripetal_sign():
    for _ in range(50):
        f, w, alpha = RNG.normal(0, 3, 3), RNG.normal(0, 0.5, 3), RNG.normal(0, 1, 2)
        at_sensor = specific_force_at_sensor(tuple(f), tuple(w), tuple(alpha), 0.5)
        back = specific_force_at_base(at_sensor, tuple(w), tuple(alpha), 0.5)
        assert back == pytest.approx(tuple(f), abs=1e-12)
    # rolling only: the mast head feels the centripetal pull towards the axis (-z)
    assert specific_force_at_sensor((0, 0, 9.81), (0.5, 0, 0), (0, 0), 1.0)[2] == \
        pytest.approx(9.81 - 0.25)


def test_velocity_of_the_mast_head():
    # pitching nose down (q > 0) moves the mast head forward
    assert sensor_point_velocity_body(1.0, 0.0, 0.0, 0.2, 1.0) == pytest.approx((1.2, 0.0))
    assert sensor_point_velocity_body(0.0, 0.0, 0.2, 0.0, 1.0) == pytest.approx((0.0, -0.2))
