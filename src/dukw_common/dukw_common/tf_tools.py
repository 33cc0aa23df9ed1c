"""Transforms on /tf and /tf_static (tf2_msgs/TFMessage, REP 105) without tf2_ros.

tf2_ros is not on PyPI; these helpers publish what its broadcasters publish, with the
same QoS, from dukw_common.description.FrameTransform values. tf2_msgs comes from the ROS
install, or on the PyPI platform from compat/tf2_msgs (built by scripts/setup.sh).
"""
from __future__ import annotations

from typing import Iterable

from geometry_msgs.msg import TransformStamped
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from tf2_msgs.msg import TFMessage

from dukw_common.description import FrameTransform

#: tf2_ros.TransformBroadcaster's QoS.
TF_QOS = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE,
                    durability=DurabilityPolicy.VOLATILE, history=HistoryPolicy.KEEP_LAST)
#: tf2_ros.StaticTransformBroadcaster's QoS: latched, the whole tree in one message.
TF_STATIC_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                           durability=DurabilityPolicy.TRANSIENT_LOCAL,
                           history=HistoryPolicy.KEEP_LAST)


def transform_msg(transform: FrameTransform, stamp) -> TransformStamped:
    """geometry_msgs/TransformStamped of one FrameTransform at ``stamp``."""
    msg = TransformStamped()
    msg.header.stamp = stamp
    msg.header.frame_id = transform.parent
    msg.child_frame_id = transform.child
    t = msg.transform.translation
    t.x, t.y, t.z = (float(v) for v in transform.xyz_m)
    r = msg.transform.rotation
    r.x, r.y, r.z, r.w = (float(v) for v in transform.quat_xyzw)
    return msg


def tf_message(transforms: Iterable[FrameTransform], stamp) -> TFMessage:
    """tf2_msgs/TFMessage of ``transforms``, all at ``stamp``."""
    return TFMessage(transforms=[transform_msg(t, stamp) for t in transforms])


def odometry_tf(odom) -> TFMessage:
    """The transform a nav_msgs/Odometry states: header.frame_id -> child_frame_id."""
    msg = TransformStamped()
    msg.header = odom.header
    msg.child_frame_id = odom.child_frame_id
    p = odom.pose.pose.position
    msg.transform.translation.x, msg.transform.translation.y = p.x, p.y
    msg.transform.translation.z = p.z
    msg.transform.rotation = odom.pose.pose.orientation
    return TFMessage(transforms=[msg])
