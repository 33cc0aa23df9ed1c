"""Messages <-> the estimator's dataclasses (used by ekf_node; no rclpy node here)."""
from __future__ import annotations

import math

import numpy as np
from nav_msgs.msg import Odometry
from sensor_msgs.msg import NavSatStatus

from dukw_common.geometry import euler_from_quaternion, quaternion_from_euler
from dukw_common.node_tools import stamp_to_s
from dukw_estimation.samples import (DepthReading, DriveStatus, GpsFix, GpsVelocity,
                                     ImuSample, MotorSide, OdometryEstimate, TractionEstimate,
                                     WaterContact)


def _var(value: float) -> float:
    """A covariance entry, or NaN when the sender did not give one (<= 0)."""
    return value if value > 0.0 else math.nan


def imu_sample(msg, t_s: float) -> ImuSample:
    """sensor_msgs/Imu -> ImuSample (orientation_covariance[0] = -1: no orientation)."""
    q = msg.orientation
    if msg.orientation_covariance[0] < 0.0:
        roll = pitch = yaw = math.nan
    else:
        roll, pitch, yaw = euler_from_quaternion(q.x, q.y, q.z, q.w)
    w, a = msg.angular_velocity, msg.linear_acceleration
    if msg.linear_acceleration_covariance[0] < 0.0:
        ax = ay = az = math.nan
    else:
        ax, ay, az = a.x, a.y, a.z
    return ImuSample(t_s, roll, pitch, yaw, w.x, w.y, w.z, ax, ay, az,
                     _var(msg.orientation_covariance[8]), _var(msg.angular_velocity_covariance[8]))


def gps_fix(msg, t_s: float) -> GpsFix:
    """sensor_msgs/NavSatFix -> GpsFix."""
    cov = msg.position_covariance
    var = _var(max(cov[0], cov[4])) if msg.position_covariance_type else math.nan
    return GpsFix(t_s, msg.latitude, msg.longitude, msg.altitude, var,
                  msg.status.status != NavSatStatus.STATUS_NO_FIX)


def gps_velocity(msg, t_s: float) -> GpsVelocity:
    """geometry_msgs/TwistWithCovarianceStamped (ENU) -> GpsVelocity."""
    lin = msg.twist.twist.linear
    cov = msg.twist.covariance
    return GpsVelocity(t_s, lin.x, lin.y, _var(max(cov[0], cov[7])))


def water_contact(msg, t_s: float) -> WaterContact:
    """dukw_msgs/WaterContact -> WaterContact."""
    return WaterContact(t_s, bool(msg.fore_wet), bool(msg.aft_wet))


def depth(msg, t_s: float) -> DepthReading:
    """dukw_msgs/Depth -> DepthReading."""
    return DepthReading(t_s, bool(msg.valid), msg.depth_m)


def drive_status(msg, t_s: float) -> DriveStatus:
    """dukw_msgs/DrivetrainStatus -> DriveStatus."""
    def side(s) -> MotorSide:
        return MotorSide(s.command_pct, s.current_a, s.speed_mps, s.force_n)
    return DriveStatus(t_s, side(msg.port), side(msg.stbd), bool(msg.connected))


#: the float fields of dukw_msgs/Traction (named as in TractionEstimate)
TRACTION_FIELDS = ('port_slip', 'stbd_slip', 'submerged_volume_m3', 'effective_weight_n',
                   'weight_on_tracks_fraction', 'waterline_distance_m', 'submerged_length_m',
                   'slope_rad', 'port_force_predicted_n', 'stbd_force_predicted_n',
                   'port_force_measured_n', 'stbd_force_measured_n')

#: subscribed topic -> its message -> sample conversion (ekf_node, replay, golden bags)
SAMPLE_FROM_MSG = {'imu/data': imu_sample, 'gps/fix': gps_fix, 'gps/vel': gps_velocity,
                   'water/contact': water_contact, 'depth': depth,
                   'tracks/status': drive_status, 'props/status': drive_status}


def odometry_msg(est: OdometryEstimate, stamp, frame_id: str, child_frame_id: str) -> Odometry:
    """OdometryEstimate -> nav_msgs/Odometry (pose in odom, twist in base_link)."""
    msg = Odometry()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.child_frame_id = child_frame_id
    pose = msg.pose.pose
    pose.position.x, pose.position.y, pose.position.z = est.x_m, est.y_m, est.z_m
    q = quaternion_from_euler(est.roll_rad, est.pitch_rad, est.yaw_rad)
    pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = q
    msg.pose.covariance = [float(v) for v in np.asarray(est.pose_cov).ravel()]
    tw = msg.twist.twist
    tw.linear.x, tw.linear.y, tw.angular.z = est.surge_mps, est.sway_mps, est.yaw_rate_rps
    msg.twist.covariance = [float(v) for v in np.asarray(est.twist_cov).ravel()]
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
