"""ros_convert.odometry_msg filling a publisher's own message: the same as a new one."""
from nav_msgs.msg import Odometry

from dukw_common.config import node_params
from dukw_common.node_tools import s_to_stamp
from dukw_common.readings import ImuSample
from dukw_estimation import ros_convert
from dukw_estimation.runner import EkfRunner


def _estimates():
    runner = EkfRunner.from_params(node_params('ekf_node'))
    out = []
    for k, yaw in enumerate((0.3, -1.2)):
        t_s = 1.0 + 0.01 * k
        runner.on_sample('imu/data', ImuSample(t_s, 0.05, -0.1, yaw, 0.0, 0.0, 0.2, 0.5, 0.0,
                                               9.81), t_s)
        out.append(runner.estimator.odometry())
    return out


def test_a_reused_message_carries_only_the_latest_estimate():
    first, second = _estimates()
    reused = Odometry()
    ros_convert.odometry_msg(first, s_to_stamp(first.t_s), 'odom', 'base_link', reused)
    filled = ros_convert.odometry_msg(second, s_to_stamp(second.t_s), 'odom', 'base_link',
                                      reused)
    fresh = ros_convert.odometry_msg(second, s_to_stamp(second.t_s), 'odom', 'base_link')
    assert filled is reused
    assert filled == fresh
    assert filled != ros_convert.odometry_msg(first, s_to_stamp(first.t_s), 'odom',
                                              'base_link')
