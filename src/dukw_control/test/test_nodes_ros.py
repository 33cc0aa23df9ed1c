"""The control nodes as processes, through real topics."""
import time

import pytest
from dukw_msgs.msg import Authority, DiffCommand, DrivetrainStatus, DriveMode, Traction
from dukw_msgs.msg import WaterContact
from dukw_msgs.srv import SetMode
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu

from dukw_common.cmd_vel import cmd_vel_type, make_cmd_vel
from dukw_common.node_tools import COMMAND_QOS, SENSOR_QOS, STATE_QOS, stamp_to_s
from dukw_common.testing import NodeProcess, ros_node, spin_until

pytestmark = pytest.mark.ros


def authority(holder):
    msg = Authority(holder=holder, reason=Authority.REASON_RC_SWITCH, rc_link_ok=True,
                    outputs_neutral=holder != Authority.HOLDER_COMPUTER, detail='test')
    return msg


def tracks_status(current_a=10.0, force_n=100.0):
    msg = DrivetrainStatus(drive=DrivetrainStatus.DRIVE_TRACKS, connected=True)
    msg.port.current_a = msg.stbd.current_a = current_a
    msg.port.force_n = msg.stbd.force_n = force_n
    return msg


def imu_now(node):
    msg = Imu()
    msg.header.stamp = node.get_clock().now().to_msg()
    msg.orientation.w = 1.0
    return msg


class Probe:
    """Publishes the controller's inputs and records tracks/cmd."""

    def __init__(self, node, stamped=True, stamp_age_s=0.0):
        self.node = node
        self.stamped, self.stamp_age_s = stamped, stamp_age_s
        self.pubs = {name: node.create_publisher(kind, name, qos) for name, kind, qos in (
            ('authority', Authority, STATE_QOS), ('drive_mode', DriveMode, STATE_QOS),
            ('cmd_vel', cmd_vel_type(stamped), COMMAND_QOS),
            ('odometry/filtered', Odometry, SENSOR_QOS),
            ('tracks/status', DrivetrainStatus, SENSOR_QOS), ('imu/data', Imu, SENSOR_QOS))}
        self.tracks = []
        node.create_subscription(DiffCommand, 'tracks/cmd', self.tracks.append, COMMAND_QOS)
        self.sending_cmd = True
        self.last_cmd_s = None
        node.create_timer(0.05, self.tick)

    def now_s(self):
        return self.node.get_clock().now().nanoseconds * 1e-9

    def tick(self):
        odom = Odometry()              # level, standing: pitch 0 for the incline guard
        odom.pose.pose.orientation.w = 1.0
        self.pubs['odometry/filtered'].publish(odom)
        self.pubs['tracks/status'].publish(tracks_status())
        self.pubs['imu/data'].publish(imu_now(self.node))
        if self.sending_cmd:
            self.last_cmd_s = self.now_s()
            self.pubs['cmd_vel'].publish(make_cmd_vel(self.stamped, 1.0, 0.0,
                                                      self.last_cmd_s - self.stamp_age_s))

    def moving(self):
        return bool(self.tracks) and self.tracks[-1].stbd_pct > 10.0


def start_driving(probe):
    mode = DriveMode(mode=DriveMode.LAND, automatic=True, track_weight=1.0, reason='test')
    probe.pubs['drive_mode'].publish(mode)
    probe.pubs['authority'].publish(authority(Authority.HOLDER_COMPUTER))


@pytest.mark.parametrize('stamped', [True, False], ids=['TwistStamped', 'Twist'])
def test_drive_controller_drives_then_goes_neutral_on_takeover_and_on_cmd_vel_loss(stamped):
    with ros_node('control_probe') as (node, executor):
        probe = Probe(node, stamped)
        start_driving(probe)
        args = ['--ros-args', '-p', f'cmd_vel_stamped:={str(stamped).lower()}']
        with NodeProcess('dukw_control', 'drive_controller_node', args) as proc:
            assert spin_until(executor, probe.moving, 30.0), proc.stderr
            assert probe.tracks[-1].port_pct > probe.tracks[-1].stbd_pct   # port bias
            # the RC operator takes over: neutral, and it stays neutral until a fresh cmd_vel
            probe.sending_cmd = False
            probe.pubs['authority'].publish(authority(Authority.HOLDER_RC))
            assert spin_until(executor, lambda: probe.tracks[-1].stbd_pct == 0.0, 5.0)
            probe.pubs['authority'].publish(authority(Authority.HOLDER_COMPUTER))
            spin_until(executor, lambda: False, 0.5)
            assert probe.tracks[-1].stbd_pct == 0.0
            probe.sending_cmd = True
            assert spin_until(executor, probe.moving, 10.0)
            # cmd_vel stops: neutral by the 0.5 s timeout (stamps of the node's clock)
            probe.sending_cmd = False
            assert spin_until(executor, lambda: probe.tracks[-1].stbd_pct == 0.0, 5.0)
            first_neutral = next(m for m in probe.tracks if m.stbd_pct == 0.0
                                 and stamp_to_s(m.header.stamp) > probe.last_cmd_s)
            delay_s = stamp_to_s(first_neutral.header.stamp) - probe.last_cmd_s
            assert delay_s <= 0.5 + 0.25, delay_s    # 0.5 s timeout + delivery slack
            count = len(probe.tracks)
        assert proc.proc.returncode == 0, proc.stderr
        spin_until(executor, lambda: len(probe.tracks) > count, 2.0)
        assert probe.tracks[-1].port_pct == 0.0 and probe.tracks[-1].stbd_pct == 0.0


def test_drive_controller_treats_a_stale_twist_stamped_as_timed_out():
    with ros_node('control_probe') as (node, executor):
        probe = Probe(node, stamped=True, stamp_age_s=0.6)     # cmd_timeout_s is 0.5 s
        start_driving(probe)
        with NodeProcess('dukw_control', 'drive_controller_node') as proc:
            assert spin_until(executor, lambda: len(probe.tracks) > 20, 30.0), proc.stderr
            spin_until(executor, lambda: False, 1.0)
            assert not any(m.stbd_pct != 0.0 for m in probe.tracks)
            probe.stamp_age_s = 0.1                             # fresh enough: it drives
            assert spin_until(executor, probe.moving, 10.0)
        assert 'treated as timed out' in proc.stderr


def test_mode_manager_publishes_land_and_obeys_set_mode():
    with ros_node('mode_probe') as (node, executor):
        modes = []
        node.create_subscription(DriveMode, 'drive_mode', modes.append, STATE_QOS)
        pubs = {name: node.create_publisher(kind, name, SENSOR_QOS) for name, kind in (
            ('water/contact', WaterContact), ('traction', Traction),
            ('tracks/status', DrivetrainStatus), ('imu/data', Imu))}

        def feed():
            pubs['imu/data'].publish(imu_now(node))
            pubs['water/contact'].publish(WaterContact())
            pubs['traction'].publish(Traction(weight_on_tracks_fraction=1.0))
            pubs['tracks/status'].publish(tracks_status())

        node.create_timer(0.05, feed)
        client = node.create_client(SetMode, 'set_mode')
        with NodeProcess('dukw_control', 'mode_manager_node') as proc:
            assert spin_until(executor, lambda: modes and modes[-1].mode == DriveMode.LAND,
                              30.0), proc.stderr
            assert modes[-1].track_weight == 1.0 and modes[-1].automatic
            assert client.wait_for_service(timeout_sec=10.0)
            future = client.call_async(SetMode.Request(mode=DriveMode.WATER, automatic=False))
            assert spin_until(executor, future.done, 10.0)
            assert not future.result().success                    # WATER on dry sand
            assert 'WATER refused' in future.result().message
            future = client.call_async(SetMode.Request(mode=DriveMode.SAFE_STOP,
                                                       automatic=False))
            assert spin_until(executor, future.done, 10.0)
            assert future.result().success
            assert spin_until(executor, lambda: modes[-1].mode == DriveMode.SAFE_STOP, 5.0)
            assert not modes[-1].automatic and 'forced' in modes[-1].reason
            future = client.call_async(SetMode.Request(automatic=True))
            assert spin_until(executor, future.done, 10.0)
            assert spin_until(executor, lambda: modes[-1].mode == DriveMode.LAND, 5.0)
        assert proc.proc.returncode == 0, proc.stderr


def test_maneuver_node_plays_with_bias_and_aborts_when_the_operator_takes_over():
    with ros_node('maneuver_probe') as (node, executor):
        tracks = []
        node.create_subscription(DiffCommand, 'tracks/cmd', tracks.append, COMMAND_QOS)
        auth = node.create_publisher(Authority, 'authority', STATE_QOS)
        status = node.create_publisher(DrivetrainStatus, 'tracks/status', SENSOR_QOS)
        node.create_timer(0.05, lambda: status.publish(tracks_status()))
        auth.publish(authority(Authority.HOLDER_COMPUTER))
        args = ['--ros-args', '-p', 'maneuver:=circle', '-p', 'duration_s:=60.0']
        with NodeProcess('dukw_control', 'maneuver_node', args) as proc:
            assert spin_until(executor, lambda: tracks and tracks[-1].stbd_pct == 100.0,
                              30.0), proc.stderr
            assert tracks[-1].port_pct == 48.0                    # 44 % + 4 % port bias
            auth.publish(authority(Authority.HOLDER_RC))
            assert spin_until(executor, lambda: tracks[-1].stbd_pct == 0.0, 5.0)
            deadline = time.monotonic() + 10.0
            while proc.alive() and time.monotonic() < deadline:
                executor.spin_once(timeout_sec=0.05)
            assert not proc.alive(), 'maneuver_node should exit after an abort'
        assert 'RC operator' in proc.stderr, proc.stderr
        assert proc.proc.returncode == 0 and 'Traceback' not in proc.stderr, proc.stderr


def test_maneuver_node_waits_for_a_first_tracks_status_after_authority():
    with ros_node('maneuver_probe') as (node, executor):
        tracks = []
        node.create_subscription(DiffCommand, 'tracks/cmd', tracks.append, COMMAND_QOS)
        auth = node.create_publisher(Authority, 'authority', STATE_QOS)
        status = node.create_publisher(DrivetrainStatus, 'tracks/status', SENSOR_QOS)
        auth.publish(authority(Authority.HOLDER_COMPUTER))     # latched, before any status
        args = ['--ros-args', '-p', 'maneuver:=circle', '-p', 'duration_s:=60.0']
        with NodeProcess('dukw_control', 'maneuver_node', args) as proc:
            assert spin_until(executor, lambda: tracks, 30.0), proc.stderr   # it runs ...
            spin_until(executor, lambda: False, 1.5)      # ... with authority, no status
            assert proc.alive() and all(m.stbd_pct == 0.0 for m in tracks), proc.stderr
            node.create_timer(0.05, lambda: status.publish(tracks_status()))
            assert spin_until(executor, lambda: tracks[-1].stbd_pct == 100.0, 10.0), \
                proc.stderr
            assert proc.alive(), proc.stderr
        assert 'stale' not in proc.stderr and 'Traceback' not in proc.stderr, proc.stderr



def test_a_separate_mode_manager_takes_the_imu_at_its_decisions_not_each_sample():
    """One process per node the IMU (only the attitude's age) is taken by the mode
    manager's companion node that no executor spins, not delivered to it at 100 Hz."""
    with NodeProcess('dukw_control', 'mode_manager_node') as proc:
        with ros_node('probe_mode_manager_imu') as (node, executor):
            def readers(topic):
                return {i.node_name for i in node.get_subscriptions_info_by_topic(topic)}
            assert spin_until(executor, lambda: 'mode_manager_node_polled' in readers(
                '/imu/data'), 30.0), proc.stderr
            assert 'mode_manager_node' not in readers('/imu/data')
            assert 'mode_manager_node' in readers('/traction')    # delivered as before
