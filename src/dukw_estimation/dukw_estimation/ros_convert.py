"""ROS messages -> the stack's sensor readings, and the estimates -> messages (no node here).

The readings' rules for covariances and validity live here (the boat's path); the
simulator's inverse (dukw_sim.sim_messages) writes messages these functions read
back to the same reading. Works on rclpy messages and on rosbags-decoded ones.
"""
from __future__ import annotations

import math

import numpy as np
from nav_msgs.msg import Odometry
from sensor_msgs.msg import NavSatStatus

from dukw_common.geometry import euler_from_quaternion, quaternion_from_euler
from dukw_common.node_tools import stamp_to_s
from dukw_common.readings import (DepthReading, DriveStatus, GpsFix, GpsVelocity, ImuSample,
                                  MotorSide, WaterContact)
from dukw_estimation.samples import OdometryEstimate, TractionEstimate

#: dukw_msgs/DrivetrainStatus.drive (DRIVE_TRACKS, DRIVE_PROPELLERS) -> DriveStatus.drive
DRIVE_NAMES = ('tracks', 'props')


def _var(value: float) -> float:
    """A covariance entry, or NaN when the sender did not give one (<= 0)."""
    return float(value) if value > 0.0 else math.nan


def _diag_var(cov) -> tuple[float, float, float]:
    """The three diagonal entries of a row-major 3x3 covariance (NaN where not given)."""
    return _var(cov[0]), _var(cov[4]), _var(cov[8])


def imu_sample(msg, t_s: float) -> ImuSample:
    """sensor_msgs/Imu -> ImuSample (covariance[0] = -1: no orientation / accelerations)."""
    q = msg.orientation
    if msg.orientation_covariance[0] < 0.0:
        roll = pitch = yaw = math.nan
        att_var = (math.nan,) * 3
    else:
        roll, pitch, yaw = euler_from_quaternion(q.x, q.y, q.z, q.w)
        att_var = _diag_var(msg.orientation_covariance)
    w, a = msg.angular_velocity, msg.linear_acceleration
    if msg.linear_acceleration_covariance[0] < 0.0:
        ax = ay = az = math.nan
        acc_var = (math.nan,) * 3
    else:
        ax, ay, az = a.x, a.y, a.z
        acc_var = _diag_var(msg.linear_acceleration_covariance)
    rate_var = _diag_var(msg.angular_velocity_covariance)
    return ImuSample(t_s, roll, pitch, yaw, w.x, w.y, w.z, ax, ay, az,
                     yaw_var_rad2=att_var[2], yaw_rate_var_rps2=rate_var[2],
                     roll_var_rad2=att_var[0], pitch_var_rad2=att_var[1],
                     roll_rate_var_rps2=rate_var[0], pitch_rate_var_rps2=rate_var[1],
                     accel_var_m2ps4=acc_var)


def gps_fix(msg, t_s: float) -> GpsFix:
    """sensor_msgs/NavSatFix -> GpsFix (horizontal: the larger of east and north)."""
    cov = msg.position_covariance
    known = bool(msg.position_covariance_type)
    horizontal = _var(max(cov[0], cov[4])) if known else math.nan
    vertical = _var(cov[8]) if known else math.nan
    return GpsFix(t_s, msg.latitude, msg.longitude, msg.altitude, horizontal,
                  msg.status.status != NavSatStatus.STATUS_NO_FIX, vertical)


def gps_velocity(msg, t_s: float) -> GpsVelocity:
    """geometry_msgs/TwistWithCovarianceStamped (ENU) -> GpsVelocity."""
    lin = msg.twist.twist.linear
    cov = msg.twist.covariance
    return GpsVelocity(t_s, lin.x, lin.y, _var(max(cov[0], cov[7])), lin.z, _var(cov[14]))


def water_contact(msg, t_s: float) -> WaterContact:
    """dukw_msgs/WaterContact -> WaterContact."""
    return WaterContact(t_s, bool(msg.fore_wet), bool(msg.aft_wet), float(msg.fore_level),
                        float(msg.aft_level))


def depth(msg, t_s: float) -> DepthReading:
    """dukw_msgs/Depth -> DepthReading."""
    return DepthReading(t_s, bool(msg.valid), msg.depth_m, msg.offset_m, msg.water_temp_c)


def motor_side(s) -> MotorSide:
    """dukw_msgs/MotorSide -> MotorSide."""
    return MotorSide(s.command_pct, s.current_a, s.speed_mps, s.force_n, s.voltage_v,
                     s.temperature_c, int(s.fault_flags), tuple(s.faults))


def drive_status(msg, t_s: float) -> DriveStatus:
    """dukw_msgs/DrivetrainStatus -> DriveStatus ('' for an unknown drive value)."""
    drive = DRIVE_NAMES[msg.drive] if msg.drive < len(DRIVE_NAMES) else ''
    return DriveStatus(t_s, motor_side(msg.port), motor_side(msg.stbd), bool(msg.connected),
                       drive)


#: the float fields of dukw_msgs/Traction (named as in TractionEstimate)
TRACTION_FIELDS = ('port_slip', 'stbd_slip', 'submerged_volume_m3', 'effective_weight_n',
                   'weight_on_tracks_fraction', 'waterline_distance_m', 'submerged_length_m',
                   'slope_rad', 'port_force_predicted_n', 'stbd_force_predicted_n',
                   'port_force_measured_n', 'stbd_force_measured_n')

#: subscribed topic -> its message -> sample conversion (ekf_node, replay, golden bags)
SAMPLE_FROM_MSG = {'imu/data': imu_sample, 'gps/fix': gps_fix, 'gps/vel': gps_velocity,
                   'water/contact': water_contact, 'depth': depth,
                   'tracks/status': drive_status, 'props/status': drive_status}


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


def stamp_or(msg, fallback_s: float) -> float:
    """The header stamp in seconds, or ``fallback_s`` when it is unset (zero)."""
    t = stamp_to_s(msg.header.stamp)
    return t if t > 0.0 else fallback_s
