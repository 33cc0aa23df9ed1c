"""mission_node through real topics: odometry in, cmd_vel and mission/status out."""
import pytest
import yaml
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from std_msgs.msg import String

from dukw_bringup.mission import MissionState, Progress, load_mission, parse_mission
from dukw_bringup.run_setup import mission_document
from dukw_common.node_tools import COMMAND_QOS, SENSOR_QOS, STATE_QOS
from dukw_common.testing import NodeProcess, ros_node, spin_until


@pytest.mark.ros
def test_mission_node_drives_towards_the_first_waypoint_and_stops_on_sigint(tmp_path):
    doc = mission_document(load_mission())
    doc['mission']['start_delay_s'] = 0.0
    mission_file = tmp_path / 'mission.yaml'
    mission_file.write_text(yaml.safe_dump(doc))
    parse_mission(yaml.safe_load(mission_file.read_text()))
    commands, statuses = [], []
    with ros_node('mission_probe') as (probe, executor):
        odom_pub = probe.create_publisher(Odometry, 'odometry/filtered', SENSOR_QOS)
        probe.create_subscription(Twist, 'cmd_vel', commands.append, COMMAND_QOS)
        probe.create_subscription(String, 'mission/status',
                                  lambda m: statuses.append(Progress.from_json(m.data)),
                                  STATE_QOS)
        odom = Odometry()
        odom.pose.pose.position.x = -10.0
        odom.pose.pose.orientation.w = 1.0       # facing the sea, on the first leg
        probe.create_timer(0.05, lambda: odom_pub.publish(odom))
        node = NodeProcess('dukw_bringup', 'mission_node',
                           ['--ros-args', '-p', f'mission_file:={mission_file}'])
        try:
            moving = spin_until(executor, lambda: any(c.linear.x > 0.5 for c in commands), 30)
            running = spin_until(executor, lambda: any(
                s.state is MissionState.RUNNING for s in statuses), 10)
        finally:
            code = node.stop()
            spin_until(executor, lambda: statuses[-1].state.finished
                       and commands[-1].linear.x == 0.0, 5)
    assert moving and running, node.stderr
    first = next(s for s in statuses if s.state is MissionState.RUNNING)
    assert first.waypoint_name == 'waterline' and first.distance_m == pytest.approx(10.0)
    assert abs(commands[-1].linear.x) < 1e-9 and abs(commands[-1].angular.z) < 1e-9
    assert statuses[-1].state is MissionState.ABORTED
    assert code == 0 and 'Traceback' not in node.stderr
