"""LatestSamples: an input taken at its reader's rate (the newest sample, once), never
woken for by the reader's executor; the companion node takes no /clock of its own."""
import pytest
from rclpy.parameter import Parameter
from sensor_msgs.msg import Imu

from dukw_common.node_tools import COMMAND_QOS, LatestSamples
from dukw_common.testing import ros_node, spin_until

pytestmark = [pytest.mark.ros, pytest.mark.timeout(60)]


def test_poll_hands_over_the_newest_sample_once_through_a_companion_node():
    with ros_node('latest_probe') as (node, executor):
        node.set_parameters([Parameter('use_sim_time', value=True)])
        taken = []
        polled = LatestSamples(node, {'latest/imu': (Imu, taken.append)})
        try:
            publisher = node.create_publisher(Imu, 'latest/imu', COMMAND_QOS)
            assert spin_until(executor, lambda: publisher.get_subscription_count() == 1, 10.0)
            for sec in (1, 2, 3):
                msg = Imu()
                msg.header.stamp.sec = sec
                publisher.publish(msg)
            spin_until(executor, lambda: False, 0.5)     # the executor spins: takes nothing
            assert polled.poll() == 1
            assert [m.header.stamp.sec for m in taken] == [3]   # only the newest
            assert polled.poll() == 0 and len(taken) == 1       # and only once
            assert node.get_subscriptions_info_by_topic('/latest/imu')[0].node_name \
                == 'latest_probe_polled'
            readers = [i.node_name for i in node.get_subscriptions_info_by_topic('/clock')]
            assert 'latest_probe_polled' not in readers and 'latest_probe' in readers
        finally:
            polled.destroy()


def test_no_inputs_no_companion_node():
    with ros_node('latest_empty') as (node, _):
        polled = LatestSamples(node, {})
        assert polled.node is None and polled.poll() == 0
        polled.destroy()
