"""Frame conversions (REP 103 vs NED/FRD) and angle helpers."""
import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from dukw_common import geometry as g

angles = st.floats(-3.0, 3.0)


@given(angles, st.floats(-1.4, 1.4), angles)
def test_quaternion_round_trip(roll, pitch, yaw):
    back = g.euler_from_quaternion(*g.quaternion_from_euler(roll, pitch, yaw))
    assert back == pytest.approx((roll, pitch, yaw), abs=1e-9)


def test_heading_north_is_enu_yaw_90_deg_and_east_is_0():
    assert g.yaw_ned_to_enu(0.0) == pytest.approx(math.pi / 2)
    assert g.yaw_ned_to_enu(math.pi / 2) == pytest.approx(0.0)
    assert g.ned_to_enu(1.0, 2.0, 3.0) == (2.0, 1.0, -3.0)
    assert g.frd_to_flu(1.0, 2.0, 3.0) == (1.0, -2.0, -3.0)


@given(st.floats(-100, 100))
def test_wrap_angle_range(a):
    w = g.wrap_angle(a)
    assert -math.pi <= w < math.pi
    assert math.sin(w) == pytest.approx(math.sin(a), abs=1e-9)


def test_body_world_rotation_inverse_and_geodetic_round_trip():
    vx, vy = g.rotate_body_to_world(0.7, 1.0, -0.3)
    assert g.rotate_world_to_body(0.7, vx, vy) == pytest.approx((1.0, -0.3))
    lat, lon, alt = g.geodetic_from_local_enu(120.0, -40.0, 2.0, 36.9, -76.0, 1.0)
    assert g.local_enu_from_geodetic(lat, lon, alt, 36.9, -76.0, 1.0) == pytest.approx(
        (120.0, -40.0, 2.0), abs=1e-6)
