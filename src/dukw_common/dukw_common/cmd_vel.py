"""cmd_vel as geometry_msgs/TwistStamped (Jazzy's convention) or Twist, one choice for all.

The shared parameter ``cmd_vel_stamped`` (config/dukw.yaml, block ``/**``) picks the type
for every node that publishes or subscribes ``cmd_vel``, so both ends always agree. Since
Jazzy, diff_drive_controller and Nav2 send TwistStamped; the stamp lets the drive
controller refuse a request that is already older than its command timeout.
"""
from __future__ import annotations

from geometry_msgs.msg import Twist, TwistStamped

from dukw_common.node_tools import ParamSpec, s_to_stamp, stamp_to_s

#: The parameter every cmd_vel publisher and subscriber declares.
CMD_VEL_STAMPED_SPEC = ParamSpec(
    'cmd_vel_stamped', 'cmd_vel is geometry_msgs/TwistStamped (true, as Jazzy) or Twist')


def cmd_vel_type(stamped: bool) -> type:
    """The message class of cmd_vel."""
    return TwistStamped if stamped else Twist


def make_cmd_vel(stamped: bool, speed_mps: float, yaw_rate_rps: float, stamp_s: float,
                 frame_id: str = 'base_link'):
    """A cmd_vel message: TwistStamped (header at ``stamp_s``) or a plain Twist."""
    twist = Twist()
    twist.linear.x = float(speed_mps)
    twist.angular.z = float(yaw_rate_rps)
    if not stamped:
        return twist
    msg = TwistStamped(twist=twist)
    msg.header.stamp = s_to_stamp(stamp_s)
    msg.header.frame_id = frame_id
    return msg


def read_cmd_vel(msg) -> tuple[float, float, float | None]:
    """(speed m/s, yaw rate rad/s, stamp s or None) of a Twist or TwistStamped.

    Works on rclpy and rosbags messages alike (duck typing on ``twist``/``header``).
    """
    if hasattr(msg, 'twist'):
        return msg.twist.linear.x, msg.twist.angular.z, stamp_to_s(msg.header.stamp)
    return msg.linear.x, msg.angular.z, None
