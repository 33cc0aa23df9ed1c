"""ROS messages -> the stack's sensor readings, and the estimates -> messages (no node here).

The readings' rules for covariances and validity live here (the boat's path); the
simulator's inverse (dukw_sim.sim_messages) writes messages these functions read
back to the same reading. Works on rclpy messages and on rosbags-decoded ones.
"""
from __future__ import annotations

import math
from operator import attrgetter

import numpy as np
from nav_msgs.msg import Odometry
from sensor_msgs.msg import NavSatStatus

from dukw_common.geometry import euler_from_quaternion, quaternion_from_euler
from dukw_common.node_tools import stamp_to_s
from dukw_common.readings import (DepthReading, DriveStatus, GpsFix, GpsVelocity, ImuSample,
                                  MotorSide, WaterContact, positional_builder)
from dukw_estimation.samples import OdometryEstimate, TractionEstimate

#: dukw_msgs/DrivetrainStatus.drive (DRIVE_TRACKS, DRIVE_PROPELLERS) -> DriveStatus.drive
DRIVE_NAMES = ('tracks', 'props')


def _var(value: float) -> float:
    """A covariance entry, or NaN when the sender did not give one (<= 0)."""
    return float(value) if value > 0.0 else math.nan


def _diag_var(cov) -> tuple[float, float, float]:
    """The three diagonal entries of a row-major 3x3 covariance (NaN where not given)."""
    return _var(cov[0]), _var(cov[4]), _var(cov[8])


#: the readings built at every IMU sample and drive status (all fields, in order)
_imu_sample = positional_builder(ImuSample)
_motor_side_fields = positional_builder(MotorSide)

#: the message fields each sample conversion reads, in the order its rule takes them: the
#: node reads them from its messages (``SAMPLE_FROM_MSG``), the offline replay as columns
#: of many messages at once (``SAMPLE_FROM_FIELDS``); the rule is the same function
IMU_FIELDS = ('orientation.x', 'orientation.y', 'orientation.z', 'orientation.w',
              'orientation_covariance', 'angular_velocity.x', 'angular_velocity.y',
              'angular_velocity.z', 'angular_velocity_covariance', 'linear_acceleration.x',
              'linear_acceleration.y', 'linear_acceleration.z',
              'linear_acceleration_covariance')


def imu_from_fields(t_s, qx, qy, qz, qw, att_cov, wx, wy, wz, rate_cov, ax, ay, az,
                    acc_cov) -> ImuSample:
    """sensor_msgs/Imu's ``IMU_FIELDS`` -> ImuSample (covariance[0] = -1: no orientation /
    accelerations)."""
    if att_cov[0] < 0.0:
        roll = pitch = yaw = math.nan
        att_var = (math.nan,) * 3
    else:
        roll, pitch, yaw = euler_from_quaternion(qx, qy, qz, qw)
        att_var = _diag_var(att_cov)
    if acc_cov[0] < 0.0:
        ax = ay = az = math.nan
        acc_var = (math.nan,) * 3
    else:
        acc_var = _diag_var(acc_cov)
    rate_var = _diag_var(rate_cov)
    # ImuSample's fields in order (variances: yaw, yaw rate, roll, pitch, roll rate, pitch
    # rate, accelerations)
    return _imu_sample(t_s, roll, pitch, yaw, wx, wy, wz, ax, ay, az, att_var[2], rate_var[2],
                       att_var[0], att_var[1], rate_var[0], rate_var[1], acc_var)


GPS_FIX_FIELDS = ('latitude', 'longitude', 'altitude', 'position_covariance',
                  'position_covariance_type', 'status.status')


def gps_fix_from_fields(t_s, latitude, longitude, altitude, cov, cov_type,
                        status) -> GpsFix:
    """sensor_msgs/NavSatFix's ``GPS_FIX_FIELDS`` -> GpsFix (horizontal: the larger of east
    and north)."""
    known = bool(cov_type)
    horizontal = _var(max(cov[0], cov[4])) if known else math.nan
    vertical = _var(cov[8]) if known else math.nan
    return GpsFix(t_s, latitude, longitude, altitude, horizontal,
                  status != NavSatStatus.STATUS_NO_FIX, vertical)


GPS_VELOCITY_FIELDS = ('twist.twist.linear.x', 'twist.twist.linear.y', 'twist.twist.linear.z',
                       'twist.covariance')


def gps_velocity_from_fields(t_s, east_mps, north_mps, up_mps, cov) -> GpsVelocity:
    """geometry_msgs/TwistWithCovarianceStamped's ``GPS_VELOCITY_FIELDS`` (ENU) ->
    GpsVelocity."""
    return GpsVelocity(t_s, east_mps, north_mps, _var(max(cov[0], cov[7])), up_mps,
                       _var(cov[14]))


WATER_CONTACT_FIELDS = ('fore_wet', 'aft_wet', 'fore_level', 'aft_level')


def water_contact_from_fields(t_s, fore_wet, aft_wet, fore_level, aft_level) -> WaterContact:
    """dukw_msgs/WaterContact's ``WATER_CONTACT_FIELDS`` -> WaterContact."""
    return WaterContact(t_s, bool(fore_wet), bool(aft_wet), float(fore_level), float(aft_level))


DEPTH_FIELDS = ('valid', 'depth_m', 'offset_m', 'water_temp_c')


def depth_from_fields(t_s, valid, depth_m, offset_m, water_temp_c) -> DepthReading:
    """dukw_msgs/Depth's ``DEPTH_FIELDS`` -> DepthReading."""
    return DepthReading(t_s, bool(valid), depth_m, offset_m, water_temp_c)


#: dukw_msgs/MotorSide's fields in MotorSide's order
MOTOR_SIDE_FIELDS = ('command_pct', 'current_a', 'speed_mps', 'force_n', 'voltage_v',
                     'temperature_c', 'fault_flags', 'faults')
DRIVE_STATUS_FIELDS = ('drive', 'connected', *(f'port.{n}' for n in MOTOR_SIDE_FIELDS),
                       *(f'stbd.{n}' for n in MOTOR_SIDE_FIELDS))


def _motor_side(command_pct, current_a, speed_mps, force_n, voltage_v, temperature_c,
                fault_flags, faults) -> MotorSide:
    return _motor_side_fields(command_pct, current_a, speed_mps, force_n, voltage_v,
                              temperature_c, int(fault_flags), tuple(faults))


def drive_status_from_fields(t_s, drive, connected, *sides) -> DriveStatus:
    """dukw_msgs/DrivetrainStatus's ``DRIVE_STATUS_FIELDS`` -> DriveStatus ('' for an unknown
    drive value); ``sides``: the port side's MotorSide fields, then the starboard's."""
    half = len(MOTOR_SIDE_FIELDS)
    return DriveStatus(t_s, _motor_side(*sides[:half]), _motor_side(*sides[half:]),
                       bool(connected), DRIVE_NAMES[drive] if drive < len(DRIVE_NAMES) else '')


#: the float fields of dukw_msgs/Traction (named as in TractionEstimate)
TRACTION_FIELDS = ('port_slip', 'stbd_slip', 'submerged_volume_m3', 'effective_weight_n',
                   'weight_on_tracks_fraction', 'waterline_distance_m', 'submerged_length_m',
                   'slope_rad', 'port_force_predicted_n', 'stbd_force_predicted_n',
                   'port_force_measured_n', 'stbd_force_measured_n')

#: subscribed topic -> (the fields its conversion reads, its rule: (t_s, *fields) -> sample)
SAMPLE_FIELDS = {'imu/data': IMU_FIELDS, 'gps/fix': GPS_FIX_FIELDS,
                 'gps/vel': GPS_VELOCITY_FIELDS, 'water/contact': WATER_CONTACT_FIELDS,
                 'depth': DEPTH_FIELDS, 'tracks/status': DRIVE_STATUS_FIELDS,
                 'props/status': DRIVE_STATUS_FIELDS}
SAMPLE_FROM_FIELDS = {'imu/data': imu_from_fields, 'gps/fix': gps_fix_from_fields,
                      'gps/vel': gps_velocity_from_fields,
                      'water/contact': water_contact_from_fields, 'depth': depth_from_fields,
                      'tracks/status': drive_status_from_fields,
                      'props/status': drive_status_from_fields}


def from_msg(fields: tuple[str, ...], rule):
    """A (msg, t_s) -> sample conversion: ``fields`` read from the message (one C call),
    handed to ``rule``."""
    read = attrgetter(*fields)

    def convert(msg, t_s: float):
        return rule(t_s, *read(msg))
    convert.__doc__ = rule.__doc__
    return convert


imu_sample = from_msg(IMU_FIELDS, imu_from_fields)
gps_fix = from_msg(GPS_FIX_FIELDS, gps_fix_from_fields)
gps_velocity = from_msg(GPS_VELOCITY_FIELDS, gps_velocity_from_fields)
water_contact = from_msg(WATER_CONTACT_FIELDS, water_contact_from_fields)
depth = from_msg(DEPTH_FIELDS, depth_from_fields)
drive_status = from_msg(DRIVE_STATUS_FIELDS, drive_status_from_fields)

#: subscribed topic -> its message -> sample conversion (ekf_node, golden bags)
SAMPLE_FROM_MSG = {topic: from_msg(SAMPLE_FIELDS[topic], SAMPLE_FROM_FIELDS[topic])
                   for topic in SAMPLE_FIELDS}


def odometry_msg(est: OdometryEstimate, stamp, frame_id: str, child_frame_id: str,
                 out: Odometry | None = None) -> Odometry:
    """OdometryEstimate -> nav_msgs/Odometry (pose in odom, twist in base_link).

    ``out``: a message to fill instead of a new one (a publisher's own, reused for each
    estimate: building an Odometry costs more than filling it). Every field this writes is
    written each time; the others stay as ``Odometry()`` made them.
    """
    msg = Odometry() if out is None else out
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.child_frame_id = child_frame_id
    pose = msg.pose.pose
    pose.position.x, pose.position.y, pose.position.z = est.x_m, est.y_m, est.z_m
    q = quaternion_from_euler(est.roll_rad, est.pitch_rad, est.yaw_rad)
    pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = q
    msg.pose.covariance = np.asarray(est.pose_cov, dtype=np.float64).ravel()  # no per-item check
    tw = msg.twist.twist
    tw.linear.x, tw.linear.y, tw.angular.z = est.surge_mps, est.sway_mps, est.yaw_rate_rps
    msg.twist.covariance = np.asarray(est.twist_cov, dtype=np.float64).ravel()
    return msg


def odometry_estimate(msg) -> OdometryEstimate:
    """nav_msgs/Odometry -> OdometryEstimate (what a subscriber of odometry/filtered reads)."""
    pose, twist = msg.pose.pose, msg.twist.twist
    q = pose.orientation
    roll, pitch, yaw = euler_from_quaternion(q.x, q.y, q.z, q.w)
    return OdometryEstimate(stamp_to_s(msg.header.stamp), pose.position.x, pose.position.y,
                            pose.position.z, roll, pitch, yaw, twist.linear.x, twist.linear.y,
                            twist.angular.z, np.reshape(msg.pose.covariance, (6, 6)),
                            np.reshape(msg.twist.covariance, (6, 6)))


def traction_estimate(msg) -> TractionEstimate:
    """dukw_msgs/Traction -> TractionEstimate."""
    return TractionEstimate(stamp_to_s(msg.header.stamp),
                            **{name: float(getattr(msg, name)) for name in TRACTION_FIELDS},
                            afloat=bool(msg.afloat))


def traction_msg(est: TractionEstimate, stamp, msg_type):
    """TractionEstimate -> dukw_msgs/Traction."""
    msg = msg_type()
    msg.header.stamp = stamp
    msg.header.frame_id = 'base_link'
    for name in TRACTION_FIELDS:
        setattr(msg, name, float(getattr(est, name)))
    msg.afloat = bool(est.afloat)
    return msg

