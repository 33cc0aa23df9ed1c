"""The composed control chain (compose: ekf, mode manager, controller in one process) through
real topics: sensors in, commands out at once, every contract topic published, authority
loss neutral at once, and no stranger on the graph able to steer it."""
import subprocess
import time

import pytest
from diagnostic_msgs.msg import DiagnosticArray
from dukw_msgs.msg import Authority, DiffCommand, DrivetrainStatus, DriveMode, Traction
from dukw_msgs.msg import WaterContact
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu
from tf2_msgs.msg import TFMessage

from dukw_common.cmd_vel import cmd_vel_type, make_cmd_vel
from dukw_common.node_tools import COMMAND_QOS, SENSOR_QOS, STATE_QOS
from dukw_common.tf_tools import TF_QOS
from dukw_common.testing import (NodeProcess, executable, moving_before_neutral,
                                  ros_node, spin_until)

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]

CHAIN = ['ekf_node', 'mode_manager_node', 'drive_controller_node']
GRAVITY_MPS2 = 9.80665
CONTRACT = {'odometry/filtered': (Odometry, SENSOR_QOS), 'traction': (Traction, SENSOR_QOS),
            '/tf': (TFMessage, TF_QOS), 'drive_mode': (DriveMode, STATE_QOS),
            'tracks/cmd': (DiffCommand, COMMAND_QOS), 'props/cmd': (DiffCommand, COMMAND_QOS),
            '/diagnostics': (DiagnosticArray, COMMAND_QOS)}


def authority(holder):
    return Authority(holder=holder, reason=Authority.REASON_RC_SWITCH, rc_link_ok=True,
                     outputs_neutral=holder != Authority.HOLDER_COMPUTER, detail='test')


class Sensors:
    """A vehicle standing level on dry sand, at 100 Hz, asked to drive at 1 m/s; records
    every contract topic with its receive time."""

    def __init__(self, node):
        self.node = node
        self.stamped = True
        self.pubs = {name: node.create_publisher(kind, name, qos) for name, kind, qos in (
            ('imu/data', Imu, SENSOR_QOS), ('tracks/status', DrivetrainStatus, SENSOR_QOS),
            ('props/status', DrivetrainStatus, SENSOR_QOS),
            ('water/contact', WaterContact, SENSOR_QOS), ('authority', Authority, STATE_QOS),
            ('cmd_vel', cmd_vel_type(self.stamped), COMMAND_QOS))}
        self.got = {topic: [] for topic in CONTRACT}
        for topic, (kind, qos) in CONTRACT.items():
            node.create_subscription(kind, topic, self._recorder(topic), qos)
        self.k = 0
        node.create_timer(0.01, self.tick)

    def _recorder(self, topic):
        return lambda msg: self.got[topic].append((time.monotonic(), msg))

    def tick(self):
        stamp = self.node.get_clock().now()
        imu = Imu()
        imu.header.stamp = stamp.to_msg()
        imu.orientation.w = 1.0
        imu.linear_acceleration.z = GRAVITY_MPS2
        self.pubs['imu/data'].publish(imu)
        self.k += 1
        if self.k % 2 == 0:
            for drive, topic in ((DrivetrainStatus.DRIVE_TRACKS, 'tracks/status'),
                                 (DrivetrainStatus.DRIVE_PROPELLERS, 'props/status')):
                status = DrivetrainStatus(drive=drive, connected=True)
                status.header.stamp = stamp.to_msg()
                self.pubs[topic].publish(status)
        if self.k % 5 == 0:
            contact = WaterContact()
            contact.header.stamp = stamp.to_msg()
            self.pubs['water/contact'].publish(contact)
            self.pubs['cmd_vel'].publish(make_cmd_vel(self.stamped, 1.0, 0.0,
                                                      stamp.nanoseconds * 1e-9))

    def tracks(self):
        return self.got['tracks/cmd']

    def moving(self):
        return bool(self.tracks()) and self.tracks()[-1][1].stbd_pct > 10.0


def drive(node, executor, sensors, proc):
    sensors.pubs['authority'].publish(authority(Authority.HOLDER_COMPUTER))
    assert spin_until(executor, sensors.moving, 40.0), proc.stderr


def test_composed_chain_drives_publishes_the_contract_and_stops_at_once_on_takeover():
    with ros_node('compose_probe') as (node, executor):
        sensors = Sensors(node)
        with NodeProcess('dukw_bringup', 'compose', CHAIN) as proc:
            drive(node, executor, sensors, proc)
            # one command pair per estimate: the controller steps on the handed estimate
            n_odom, n_cmd = len(sensors.got['odometry/filtered']), len(sensors.tracks())
            spin_until(executor, lambda: False, 1.0)
            odom_rate = len(sensors.got['odometry/filtered']) - n_odom
            cmd_rate = len(sensors.tracks()) - n_cmd
            assert odom_rate >= 20 and cmd_rate >= 0.7 * odom_rate, (odom_rate, cmd_rate)
            assert all(sensors.got[t] for t in CONTRACT), {t: len(v) for t, v in
                                                           sensors.got.items()}
            names = {s.name.split(':')[0] for _, a in sensors.got['/diagnostics']
                     for s in a.status}
            assert set(CHAIN) <= names
            assert sensors.got['drive_mode'][-1][1].mode == DriveMode.LAND
            # the RC operator takes over: the next command is neutral, within one step
            sent = time.monotonic()
            sensors.pubs['authority'].publish(authority(Authority.HOLDER_RC))
            assert spin_until(executor,
                              lambda: sensors.tracks()[-1][1].stbd_pct == 0.0, 5.0)
            after = [(t, m) for t, m in sensors.tracks() if t > sent]
            first_neutral = next(t for t, m in after if m.stbd_pct == 0.0)
            # within one step: one command in flight, one tick due at the same wake-up
            late = moving_before_neutral(sensors.tracks(), sent)
            assert late <= 2, f'{late} moving commands in {first_neutral - sent:.3f} s'
            moving_after = [t for t, m in after if m.stbd_pct != 0.0 and t > first_neutral]
            assert not moving_after
        assert proc.proc.returncode == 0, proc.stderr


def test_composed_chain_ignores_a_strangers_odometry_and_refuses_a_second_drive_mode():
    with ros_node('compose_probe') as (node, executor):
        sensors = Sensors(node)
        stranger_odom = node.create_publisher(Odometry, 'odometry/filtered', SENSOR_QOS)

        def steep():           # 30 deg nose up: the incline guard would stop a listener
            odom = Odometry()
            odom.pose.pose.orientation.y, odom.pose.pose.orientation.w = -0.2588, 0.9659
            stranger_odom.publish(odom)
        node.create_timer(0.01, steep)
        with NodeProcess('dukw_bringup', 'compose', CHAIN) as proc:
            drive(node, executor, sensors, proc)
            spin_until(executor, lambda: False, 1.0)
            assert sensors.moving()                  # the estimate comes from its own EKF
            # a second drive_mode source: neutral (one-source rule), ERROR in /diagnostics
            spoof = node.create_publisher(DriveMode, 'drive_mode', STATE_QOS)
            spoof.publish(DriveMode(mode=DriveMode.LAND, automatic=True, track_weight=1.0,
                                    reason='spoof'))
            assert spin_until(executor, lambda: sensors.tracks()[-1][1].stbd_pct == 0.0, 5.0)
            assert spin_until(executor, lambda: any(
                'second source' in s.message or 'sources' in s.message
                for _, a in sensors.got['/diagnostics'][-5:] for s in a.status), 5.0)
        assert proc.proc.returncode == 0, proc.stderr


def test_compose_refuses_an_unknown_node():
    done = subprocess.run([str(executable('dukw_bringup', 'compose')), 'ekf_node', 'no_node'],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    assert 'usage: compose' in done.stderr


def test_the_command_goes_out_before_the_observers_odometry_in_the_imu_callback():
    """In the composed process the controller steps on the estimate and tracks/cmd is
    published before ekf_node builds and publishes odometry/filtered for the observers."""
    import rclpy

    from dukw_bringup import compose
    from dukw_common.config import default_config_path
    rclpy.init(args=['--ros-args', '--params-file', str(default_config_path()),
                     '--log-level', 'error'])
    nodes = compose.build(CHAIN)
    try:
        ekf, controller = nodes[0], nodes[-1]
        order = []
        for name, publisher in (('odometry/filtered', ekf.odom_pub),
                                ('tracks/cmd', controller.commands.tracks)):
            publisher.publish = (lambda msg, n=name, p=publisher.publish:
                                 (order.append(n), p(msg)))
        on_imu = next(sub.callback for node in nodes for sub in node.subscriptions
                      if sub.topic_name == '/imu/data')
        for _ in range(20):
            imu = Imu()
            imu.header.stamp = ekf.get_clock().now().to_msg()
            imu.orientation.w = 1.0
            imu.linear_acceleration.z = GRAVITY_MPS2
            on_imu(imu)
            time.sleep(0.01)
        assert order.count('odometry/filtered') >= 10
        pairs = list(zip(order[::2], order[1::2], strict=True))
        assert set(pairs) == {('tracks/cmd', 'odometry/filtered')}
    finally:
        for node in reversed(nodes):
            node.destroy_node()
        rclpy.try_shutdown()
