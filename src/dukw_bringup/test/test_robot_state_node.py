"""robot_state_node through real topics: the URDF and /tf_static, latched, from config."""
import xml.etree.ElementTree as ET

import pytest
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

from dukw_common.node_tools import STATE_QOS
from dukw_common.testing import NodeProcess, ros_node, spin_until
from dukw_common.tf_tools import TF_STATIC_QOS
from dukw_common.vehicle import Vehicle

pytestmark = pytest.mark.ros


def test_latched_description_and_static_frames_reach_a_late_subscriber():
    sensors = Vehicle.load().sensors
    with NodeProcess('dukw_bringup', 'robot_state_node',
                     ['--ros-args', '-p', 'sensors.imu_z_m:=0.55']) as proc:
        with ros_node('description_probe') as (node, executor):
            descriptions, statics = [], []
            # subscribed after the node published once: transient local must deliver it
            spin_until(executor, lambda: False, 1.0)
            node.create_subscription(String, 'robot_description', descriptions.append,
                                     STATE_QOS)
            node.create_subscription(TFMessage, '/tf_static', statics.append, TF_STATIC_QOS)
            assert spin_until(executor, lambda: descriptions and statics, 30.0), proc.stderr
    assert proc.proc.returncode == 0, proc.stderr
    robot = ET.fromstring(descriptions[-1].data)
    joints = {j.find('child').get('link'): j.find('origin').get('xyz')
              for j in robot.findall('joint')}
    frames = {t.child_frame_id: t for t in statics[-1].transforms}
    assert set(frames) == set(joints)
    assert all(t.header.frame_id == 'base_link' for t in frames.values())
    assert frames['imu_link'].transform.translation.z == pytest.approx(0.55)   # the override
    assert joints['imu_link'] == '0 0 0.55'
    gps = frames['gps_link'].transform.translation
    assert (gps.x, gps.z) == pytest.approx((0.0, sensors.gps_antenna_z_m))
    fore = frames['fore_water_link'].transform.translation
    assert (fore.x, fore.z) == pytest.approx((sensors.fore_water_x_m, sensors.fore_water_z_m))
    assert frames['depth_sounder_link'].transform.translation.z == pytest.approx(
        sensors.depth_sounder_z_m)


def test_its_own_process_takes_no_clock_under_sim_time():
    """The node reads no clock after its one publication: under use_sim_time (every node of
    `bringup sim` but the simulator) it must not keep a 100 Hz /clock subscription."""
    with NodeProcess('dukw_bringup', 'robot_state_node',
                     ['--ros-args', '-p', 'use_sim_time:=true']) as proc:
        with ros_node('clock_probe') as (node, executor):
            descriptions = []
            node.create_subscription(String, 'robot_description', descriptions.append,
                                     STATE_QOS)
            assert spin_until(executor, lambda: descriptions, 30.0), proc.stderr

            def clock_readers():
                return [i.node_name for i in node.get_subscriptions_info_by_topic('/clock')]
            spin_until(executor, lambda: False, 1.0)     # the graph settles
            # a remote endpoint's node name can be discovered after the endpoint
            spin_until(executor, lambda: '_NODE_NAME_UNKNOWN_' not in clock_readers(), 10.0)
            assert node.get_publishers_info_by_topic('/tf_static')   # its endpoints are known
            assert 'robot_state_node' not in clock_readers()
