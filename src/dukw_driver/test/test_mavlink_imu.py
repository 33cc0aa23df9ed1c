"""MAVLink IMU decoding, pymavlink on the far side; NED/FRD -> ENU/FLU with known numbers."""
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pymavlink.dialects.v20 import common as mavlink

from dukw_common.geometry import euler_from_quaternion
from dukw_driver.gnss import CovarianceKind, FixStatus, GnssFix, GnssVelocity, UereSettings
from dukw_driver.mavlink_imu import (DecodedImu, ImuSettings, MavlinkImuDecoder,
                                     orientation_enu_flu_from_euler_ned,
                                     orientation_enu_flu_from_ned_frd)

SETTINGS = ImuSettings(orientation_std_rad=(0.01, 0.01, 0.03),
                       gyro_std_rps=math.radians(0.172), accel_std_mps2=(0.010, 0.009, 0.009),
                       velocity_std_mps=0.1, uere=UereSettings(4.0, 0.7))
ENCODER = mavlink.MAVLink(None, srcSystem=1, srcComponent=1)


def pack(msg):
    return msg.pack(ENCODER)


def attitude(roll=0.0, pitch=0.0, yaw=0.0, p=0.0, q=0.0, r=0.0):
    return pack(mavlink.MAVLink_attitude_message(1000, roll, pitch, yaw, p, q, r))


def quaternion_message(q_wxyz, p=0.0, q=0.0, r=0.0):
    return pack(mavlink.MAVLink_attitude_quaternion_message(1000, *q_wxyz, p, q, r))


def test_heading_north_level_is_yaw_plus_90_deg_in_enu():
    (sample,) = MavlinkImuDecoder(SETTINGS).feed(attitude(yaw=0.0), 0.0)
    assert isinstance(sample, DecodedImu)
    roll, pitch, yaw = euler_from_quaternion(*sample.orientation_xyzw)
    assert (roll, pitch) == pytest.approx((0.0, 0.0), abs=1e-7)
    assert yaw == pytest.approx(math.pi / 2)


def test_heading_east_is_yaw_zero_and_west_is_pi():
    assert euler_from_quaternion(*orientation_enu_flu_from_euler_ned(0, 0, math.pi / 2))[2] \
        == pytest.approx(0.0, abs=1e-9)
    assert abs(euler_from_quaternion(*orientation_enu_flu_from_euler_ned(
        0, 0, -math.pi / 2))[2]) == pytest.approx(math.pi)


def test_turning_to_port_is_a_positive_yaw_rate_in_flu():
    # heading north, turning to port (towards west): the NED yaw rate is negative
    (sample,) = MavlinkImuDecoder(SETTINGS).feed(attitude(yaw=0.0, r=-0.2), 0.0)
    assert sample.angular_velocity_flu_rps == pytest.approx((0.0, 0.0, 0.2))


def test_nose_up_and_starboard_down_in_flu():
    # FRD pitch +0.1 (nose up) is FLU pitch -0.1 (REP 103: positive pitch is nose down);
    # FRD roll +0.2 (starboard down) stays +0.2 about the forward axis
    (sample,) = MavlinkImuDecoder(SETTINGS).feed(
        attitude(roll=0.2, pitch=0.1, yaw=0.0, p=0.01, q=0.02), 0.0)
    roll, pitch, _ = euler_from_quaternion(*sample.orientation_xyzw)
    assert (roll, pitch) == pytest.approx((0.2, -0.1))
    assert sample.angular_velocity_flu_rps == pytest.approx((0.01, -0.02, 0.0))


@settings(max_examples=200, deadline=None)
@given(st.floats(-1.2, 1.2), st.floats(-1.2, 1.2), st.floats(-3.1, 3.1))
def test_quaternion_and_euler_paths_agree(roll, pitch, yaw):
    # the device's own quaternion for these NED/FRD Euler angles (ZYX), w first
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    q_ned = (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
             cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)
    via_quaternion = orientation_enu_flu_from_ned_frd(q_ned)
    via_euler = orientation_enu_flu_from_euler_ned(roll, pitch, yaw)
    dot = abs(sum(a * b for a, b in zip(via_quaternion, via_euler, strict=True)))
    assert dot == pytest.approx(1.0, abs=1e-9)


def test_attitude_quaternion_preferred_once_seen():
    dec = MavlinkImuDecoder(SETTINGS)
    half = math.sqrt(0.5)
    out = dec.feed(quaternion_message((half, 0.0, 0.0, half)) + attitude(yaw=0.0), 0.0)
    assert len(out) == 1   # the ATTITUDE after it is ignored
    # NED heading east (90 deg about down) is ENU yaw 0
    assert euler_from_quaternion(*out[0].orientation_xyzw)[2] == pytest.approx(0.0, abs=1e-7)
    assert dec.counters.ignored == 1


def test_vehicle_at_rest_measures_plus_g_up_in_flu_with_configured_covariances():
    dec = MavlinkImuDecoder(SETTINGS)
    dec.feed(pack(mavlink.MAVLink_scaled_imu_message(1000, 10, -20, -1000, 0, 0, 0, 0, 0, 0)),
             0.0)
    (sample,) = dec.feed(attitude(), 0.1)
    assert sample.linear_acceleration_flu_mps2 == pytest.approx(
        (0.0980665, 0.196133, 9.80665))
    assert sample.linear_acceleration_covariance[0] == pytest.approx(0.010 ** 2)
    assert sample.linear_acceleration_covariance[4] == pytest.approx(0.009 ** 2)
    assert sample.angular_velocity_covariance[8] == pytest.approx(math.radians(0.172) ** 2)
    assert sample.orientation_covariance[8] == pytest.approx(0.03 ** 2)


def test_highres_imu_wins_over_raw_and_stale_accel_is_unknown():
    dec = MavlinkImuDecoder(SETTINGS)
    dec.feed(pack(mavlink.MAVLink_highres_imu_message(
        1, 0.5, 0.0, -9.8, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xFFFF)), 0.0)
    dec.feed(pack(mavlink.MAVLink_raw_imu_message(1, 0, 0, -500, 0, 0, 0, 0, 0, 0)), 0.0)
    (sample,) = dec.feed(attitude(), 0.1)
    assert sample.linear_acceleration_flu_mps2 == pytest.approx((0.5, 0.0, 9.8))
    (late,) = dec.feed(attitude(), 2.0)
    assert late.linear_acceleration_flu_mps2 is None
    assert late.linear_acceleration_covariance[0] == -1.0


def test_gps_raw_int_fix_with_reported_accuracy():
    msg = mavlink.MAVLink_gps_raw_int_message(
        1, 3, 367000000, -1218000000, 10000, 90, 150, 0, 0, 12,
        alt_ellipsoid=-20000, h_acc=1500, v_acc=3000, vel_acc=200)
    (fix,) = MavlinkImuDecoder(SETTINGS).feed(pack(msg), 0.0)
    assert isinstance(fix, GnssFix)
    assert fix.status == FixStatus.FIX
    assert (fix.latitude_deg, fix.longitude_deg) == pytest.approx((36.7, -121.8))
    assert fix.altitude_m == pytest.approx(-20.0)
    assert fix.covariance_enu_m2 == pytest.approx((2.25, 2.25, 9.0))
    assert fix.covariance_kind == CovarianceKind.DIAGONAL_KNOWN


def test_gps_raw_int_without_accuracy_uses_hdop_and_no_fix_is_nan():
    dec = MavlinkImuDecoder(SETTINGS)
    (fix,) = dec.feed(pack(mavlink.MAVLink_gps_raw_int_message(
        1, 3, 367000000, -1218000000, 10000, 200, 65535, 0, 0, 12)), 0.0)
    assert fix.covariance_kind == CovarianceKind.APPROXIMATED
    assert fix.covariance_enu_m2[0] == pytest.approx((2.0 * 4.0) ** 2)
    (none,) = dec.feed(pack(mavlink.MAVLink_gps_raw_int_message(
        1, 1, 0, 0, 0, 65535, 65535, 0, 0, 0)), 0.0)
    assert none.status == FixStatus.NO_FIX and math.isnan(none.latitude_deg)


def test_global_position_velocity_ned_to_enu():
    msg = mavlink.MAVLink_global_position_int_message(1, 0, 0, 0, 0, 100, -50, 20, 0)
    (vel,) = MavlinkImuDecoder(SETTINGS).feed(pack(msg), 0.0)
    assert isinstance(vel, GnssVelocity)
    assert (vel.east_mps, vel.north_mps, vel.up_mps) == pytest.approx((-0.5, 1.0, -0.2))
    assert vel.variance_enu == pytest.approx((0.01, 0.01, 0.01))


def test_global_position_velocity_is_valid_only_with_a_gps_fix():
    dec = MavlinkImuDecoder(SETTINGS)
    vel_msg = mavlink.MAVLink_global_position_int_message(1, 0, 0, 0, 0, 0, 0, 0, 0)
    assert not dec.feed(pack(vel_msg), 0.0)[0].valid            # no GPS_RAW_INT yet
    for fix_type, valid in ((1, False), (3, True), (0, False)):
        raw = mavlink.MAVLink_gps_raw_int_message(1, fix_type, 0, 0, 0, 65535, 65535, 0, 0, 0)
        dec.feed(pack(raw), 0.0)
        assert dec.feed(pack(vel_msg), 0.0)[0].valid is valid


def test_nan_attitude_and_bad_quaternion_are_parse_errors():
    dec = MavlinkImuDecoder(SETTINGS)
    assert dec.feed(attitude(roll=math.nan), 0.0) == []
    assert dec.feed(quaternion_message((0.1, 0.0, 0.0, 0.1)), 0.0) == []
    assert dec.counters.parse_errors == 2


def test_a_corrupted_packet_is_counted_and_the_next_decodes():
    dec = MavlinkImuDecoder(SETTINGS)
    bad = bytearray(attitude(yaw=0.3))
    bad[15] ^= 0x55
    out = dec.feed(bytes(bad) + attitude(yaw=0.3), 0.0)
    assert len(out) == 1
    assert dec.counters.frame_errors >= 1


def test_a_truncated_packet_costs_only_itself():
    dec = MavlinkImuDecoder(SETTINGS)
    good = [attitude(yaw=0.1 * i) for i in range(5)]
    out = dec.feed(good[0][:3] + b''.join(good), 0.0)
    assert len(out) == 5
    assert dec.counters.frame_errors >= 1


PACKETS = [attitude(0.1, 0.2, 0.3), quaternion_message((1.0, 0.0, 0.0, 0.0)),
           pack(mavlink.MAVLink_scaled_imu_message(1, 1, 2, -1000, 3, 4, 5, 0, 0, 0)),
           pack(mavlink.MAVLink_gps_raw_int_message(1, 3, 1, 2, 3, 90, 150, 0, 0, 12)),
           pack(mavlink.MAVLink_global_position_int_message(1, 0, 0, 0, 0, 1, 2, 3, 0)),
           pack(mavlink.MAVLink_heartbeat_message(2, 3, 0, 0, 4, 3))]


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(st.sampled_from(PACKETS), st.integers(0, 60), st.integers(1, 255),
                          st.sampled_from(['flip', 'truncate', 'keep'])), max_size=8),
       st.binary(max_size=64), st.integers(1, 64))
def test_truncated_corrupted_and_random_bytes_never_raise(parts, noise, chunk):
    dec = MavlinkImuDecoder(SETTINGS)
    stream, damaged = bytearray(noise), 0
    for packet, position, flip, how in parts:
        data = bytearray(packet)
        if how == 'flip':
            data[position % len(data)] ^= flip
        elif how == 'truncate':
            data = data[:1 + position % (len(data) - 1)]
        damaged += how != 'keep'
        stream += data
    stream += b''.join(PACKETS) * 8   # good packets after the damage
    out = []
    for i in range(0, len(stream), chunk):
        out += dec.feed(bytes(stream[i:i + chunk]), 0.0)
    for item in out:
        assert isinstance(item, (DecodedImu, GnssFix, GnssVelocity))
    # resynchronised: the good packets after the damage decode. A damaged frame that reads
    # as an unknown id cannot be CRC-checked; when a start marker follows it by chance, the
    # good bytes it swallowed (at most 280, about one copy of PACKETS) are lost
    kinds = ('ATTITUDE_QUATERNION', 'SCALED_IMU', 'GPS_RAW_INT', 'GLOBAL_POSITION_INT',
             'HEARTBEAT')
    assert min(dec.counters.by_type.get(kind, 0) for kind in kinds) >= 6
    if damaged:
        # a flipped message id gives a well-framed packet of an unknown id: not an error
        assert dec.counters.errors + dec.counters.unknown_ids >= 1
