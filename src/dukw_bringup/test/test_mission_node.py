"""mission_node through real topics: odometry in, cmd_vel and mission/status out."""
import pytest
import yaml
from nav_msgs.msg import Odometry
from std_msgs.msg import String

from dukw_bringup.mission import MissionState, Progress, load_mission, parse_mission
from dukw_bringup.run_setup import mission_document
from dukw_common.cmd_vel import cmd_vel_type, read_cmd_vel
from dukw_common.node_tools import COMMAND_QOS, SENSOR_QOS, STATE_QOS
from dukw_common.testing import NodeProcess, ros_node, spin_until

UNKNOWN_NODE = '_NODE_NAME_UNKNOWN_'   # rmw's name before a node's name is discovered


@pytest.mark.ros
@pytest.mark.parametrize('stamped', [True, False], ids=['TwistStamped', 'Twist'])
def test_mission_node_drives_towards_the_first_waypoint_and_stops_on_sigint(tmp_path, stamped):
    doc = mission_document(load_mission())
    doc['mission']['start_delay_s'] = 0.0
    mission_file = tmp_path / 'mission.yaml'
    mission_file.write_text(yaml.safe_dump(doc))
    parse_mission(yaml.safe_load(mission_file.read_text()))
    commands, statuses = [], []
    with ros_node('mission_probe') as (probe, executor):
        odom_pub = probe.create_publisher(Odometry, 'odometry/filtered', SENSOR_QOS)
        probe.create_subscription(cmd_vel_type(stamped), 'cmd_vel',
                                  lambda m: commands.append(read_cmd_vel(m)), COMMAND_QOS)
        probe.create_subscription(String, 'mission/status',
                                  lambda m: statuses.append(Progress.from_json(m.data)),
                                  STATE_QOS)
        odom = Odometry()
        odom.pose.pose.position.x = -10.0
        odom.pose.pose.orientation.w = 1.0       # facing the sea, on the first leg
        probe.create_timer(0.05, lambda: odom_pub.publish(odom))
        node = NodeProcess('dukw_bringup', 'mission_node',
                           ['--ros-args', '-p', f'mission_file:={mission_file}',
                            '-p', f'cmd_vel_stamped:={str(stamped).lower()}'])
        try:
            moving = spin_until(executor, lambda: any(c[0] > 0.5 for c in commands), 30)
            running = spin_until(executor, lambda: any(
                s.state is MissionState.RUNNING for s in statuses), 10)
            # the newest pose is taken at each 20 Hz tick, not delivered at 100 Hz; a remote
            # endpoint's node name can be discovered after the endpoint: wait for the name

            def odometry_readers():
                return {i.node_name
                        for i in probe.get_subscriptions_info_by_topic('/odometry/filtered')}
            spin_until(executor, lambda: odometry_readers()
                       and UNKNOWN_NODE not in odometry_readers(), 10)
            readers = odometry_readers()
        finally:
            code = node.stop()
            spin_until(executor, lambda: statuses[-1].state.finished
                       and commands[-1][0] == 0.0, 5)
    assert moving and running, node.stderr
    assert readers == {'mission_node_polled'}
    first = next(s for s in statuses if s.state is MissionState.RUNNING)
    assert first.waypoint_name == 'waterline' and first.distance_m == pytest.approx(10.0)
    assert abs(commands[-1][0]) < 1e-9 and abs(commands[-1][1]) < 1e-9
    stamps = [c[2] for c in commands]
    if stamped:
        assert all(t is not None and t > 0.0 for t in stamps)
    else:
        assert stamps == [None] * len(stamps)
    assert statuses[-1].state is MissionState.ABORTED
    assert code == 0 and 'Traceback' not in node.stderr
