"""shore_link_node against a real pymavlink ground station over UDP loopback and a pty radio."""
import json
import os
import time

import pytest
from dukw_msgs.srv import SetMode
from geometry_msgs.msg import TwistStamped
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from nav_msgs.msg import Odometry
from pymavlink import mavutil
from pymavlink.dialects.v20 import common as mavlink
from std_msgs.msg import Bool, String

from dukw_common.node_tools import COMMAND_QOS, SENSOR_QOS, STATE_QOS
from dukw_common.testing import NodeProcess, ros_node, spin_until
from dukw_driver.mavlink_signing import signing_timestamp
from dukw_driver.shore_link_node import ShoreLinkNode
from node_graph import NodeGraph
from shore_gcs import KEY, WRONG_KEY, Gcs

pytestmark = [pytest.mark.ros, pytest.mark.timeout(120)]


def odometry(x_m):
    msg = Odometry()
    msg.pose.pose.position.x = x_m
    msg.pose.pose.orientation.w = 1.0
    msg.twist.twist.linear.x = 0.5
    return msg


class UdpGraph(NodeGraph):
    """The node on udpout to a signed mavutil ground station (udpin); the probe is the stack."""

    def __init__(self, probe, executor, key_file, **overrides):
        os.environ['MAVLINK20'] = '1'          # mavutil: the MAVLink 2 common dialect
        self.gcs = mavutil.mavlink_connection('udpin:127.0.0.1:0', source_system=255,
                                              source_component=190, dialect='common')
        self.gcs.setup_signing(KEY, sign_outgoing=True, link_id=1)
        port = self.gcs.port.getsockname()[1]
        super().__init__(probe, executor, ShoreLinkNode, url=f'udpout:127.0.0.1:{port}',
                         signing_key_file=str(key_file), **overrides)
        self.cmd = self.record(TwistStamped, 'cmd_vel', qos=COMMAND_QOS)
        self.plans = self.record(String, 'mission/plan', qos=STATE_QOS)
        self.holds = self.record(Bool, 'mission/hold', qos=STATE_QOS)
        self.odom_pub = probe.create_publisher(Odometry, 'odometry/filtered', SENSOR_QOS)
        self.seen: list = []

    def pump(self, seconds, predicate=lambda: False, every=None):
        """Spin and read the GCS side until ``predicate()`` or ``seconds`` pass."""
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            self.executor.spin_once(timeout_sec=0.01)
            while (msg := self.gcs.recv_match(blocking=False)) is not None:
                if msg.get_type() != 'BAD_DATA':
                    self.seen.append(msg)
            if every:
                every()
            if predicate():
                return True
        return predicate()

    def of_type(self, kind):
        return [m for m in self.seen if m.get_type() == kind]


@pytest.fixture
def key_file(tmp_path):
    path = tmp_path / 'shore.key'
    path.write_text(KEY.hex())
    return path


@pytest.fixture
def graph(key_file):
    with ros_node('probe_shore') as (probe, executor):
        graph = UdpGraph(probe, executor, key_file)
        yield graph
        graph.close()
        graph.gcs.close()


def test_gcs_sees_signed_heartbeat_and_the_position_move(graph):
    x = [0.0]

    def drive():
        x[0] += 0.05
        graph.odom_pub.publish(odometry(x[0]))
    assert graph.pump(15.0, lambda: len(graph.of_type('GLOBAL_POSITION_INT')) >= 8, drive)
    heartbeats = graph.of_type('HEARTBEAT')
    assert heartbeats and heartbeats[-1].type == mavlink.MAV_TYPE_GROUND_ROVER
    assert [m.get_type() for m in graph.seen if not m.get_signed()] == []
    lons = [m.lon for m in graph.of_type('GLOBAL_POSITION_INT')]
    assert lons[-1] > lons[0]                                     # moving east (odom x)


def test_manual_control_drives_cmd_vel_and_its_loss_stops_it(graph):
    graph.pump(1.0)
    sent = []

    def manual():
        if len(sent) < 20:
            graph.gcs.mav.manual_control_send(1, 600, 0, 500, 0, 0)
            sent.append(time.monotonic())
    assert graph.pump(10.0, lambda: any(abs(c.twist.linear.x - 0.6) < 1e-9
                                        for c in graph.cmd),
                      manual)
    graph.pump(10.0, lambda: len(sent) >= 20, manual)
    last_s = sent[-1]
    assert graph.pump(2.0, lambda: graph.cmd[-1].twist.linear.x == 0.0)
    stop_after_s = time.monotonic() - last_s
    assert stop_after_s < 0.5 + 0.1, stop_after_s                 # 0.1 s: this loop's polling
    assert graph.holds and graph.holds[0].data is True            # a running mission is held


def test_strangers_and_replays_are_rejected_without_locking_out_the_key(graph):
    graph.pump(1.0)
    real = Gcs(link_id=1)
    stranger = Gcs(key=WRONG_KEY, link_id=1)
    stranger.mav.signing.timestamp = signing_timestamp(time.time() + 86400.0)
    unsigned = Gcs(key=None)
    good = real.manual(400)
    for packet in (stranger.manual(1000), unsigned.manual(1000), good, good):
        graph.gcs.write(packet)
        graph.pump(0.2)
    assert [round(c.twist.linear.x, 3) for c in graph.cmd if c.twist.linear.x] == [0.4]
    graph.cmd.clear()
    graph.gcs.write(real.manual(300))                              # the real key still works
    assert graph.pump(3.0, lambda: any(abs(c.twist.linear.x - 0.3) < 1e-9 for c in graph.cmd))
    assert graph.pump(5.0, lambda: graph.value('shore link', 'rejected_replayed') == '1')
    assert graph.value('shore link', 'rejected_bad_signature') == '1'
    assert graph.value('shore link', 'rejected_unsigned') == '1'


def test_mode_request_goes_through_set_mode_and_is_acknowledged(graph):
    calls = []

    def serve(request, response):
        calls.append((request.mode, request.automatic))
        response.success, response.message = True, 'ok'
        return response
    graph.probe.create_service(SetMode, 'set_mode', serve)
    graph.pump(1.0)
    graph.gcs.mav.command_long_send(1, 1, mavlink.MAV_CMD_DO_SET_MODE, 0,
                                    mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 2, 0, 0, 0, 0, 0)
    assert graph.pump(10.0, lambda: graph.of_type('COMMAND_ACK'))
    assert calls == [(2, False)]
    assert graph.of_type('COMMAND_ACK')[-1].result == mavlink.MAV_RESULT_ACCEPTED


def test_mission_upload_reaches_the_mission_node_topic(graph):
    graph.pump(1.0)
    lat, lon = int(36.1836e7), int(-75.7510e7)
    items = [(lat, lon - 700), (lat + 400, lon - 700)]             # ~6 m west, then ~4 m north
    graph.gcs.mav.mission_count_send(1, 1, len(items), 0)
    acks = []

    def answer():
        for req in graph.of_type('MISSION_REQUEST_INT'):
            if not getattr(req, 'answered', False):
                req.answered = True
                graph.gcs.mav.mission_item_int_send(
                    1, 1, req.seq, mavlink.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
                    mavlink.MAV_CMD_NAV_WAYPOINT, 0, 1, 0, 0, 0, 0, *items[req.seq], 0, 0)
        acks[:] = graph.of_type('MISSION_ACK')
    assert graph.pump(10.0, lambda: acks and graph.plans, answer)
    assert acks[-1].type == mavlink.MAV_MISSION_ACCEPTED
    waypoints = json.loads(graph.plans[-1].data)['waypoints']
    assert [round(w['x_m']) for w in waypoints] == [-6, -6]
    assert [round(w['y_m']) for w in waypoints] == [0, 4]
    graph.gcs.mav.command_long_send(1, 1, mavlink.MAV_CMD_MISSION_START, 0, 0, 0, 0, 0, 0, 0, 0)
    assert graph.pump(5.0, lambda: graph.holds and graph.holds[-1].data is False)


@settings(max_examples=25, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(st.lists(st.binary(min_size=1, max_size=280), min_size=1, max_size=5))
def test_fuzzed_datagrams_never_crash_the_node(graph, datagrams):
    for data in datagrams:
        graph.gcs.write(data)
    before = len(graph.of_type('HEARTBEAT'))
    assert graph.pump(5.0, lambda: len(graph.of_type('HEARTBEAT')) > before)


def test_installed_node_over_a_pty_radio_keeps_its_timestamps(tmp_path, key_file):
    master, slave = os.openpty()
    tty = os.ttyname(slave)
    args = ['--ros-args', '-p', f'url:={tty},57600', '-p', f'signing_key_file:={key_file}']
    gcs = Gcs(link_id=2)
    os.set_blocking(master, False)
    with ros_node('probe_shore_pty') as (probe, executor):
        cmds = []
        probe.create_subscription(TwistStamped, 'cmd_vel', cmds.append, COMMAND_QOS)
        proc = NodeProcess('dukw_driver', 'shore_link_node', args)
        try:
            def read_radio():
                try:
                    gcs.feed(os.read(master, 4096))
                except BlockingIOError:
                    pass
                return bool(gcs.of_type('HEARTBEAT'))
            assert spin_until(executor, read_radio, 30.0), proc.stop() and proc.stderr
            assert all(m.get_signed() for m in gcs.received)
            assert spin_until(executor, lambda: probe.count_publishers('cmd_vel') > 0, 20.0)

            def joystick():                    # sticks at 0.7 while the radio is read
                os.write(master, gcs.manual(700))
                read_radio()
                return any(c.twist.linear.x == 0.7 for c in cmds)
            assert spin_until(executor, joystick, 15.0)
            assert spin_until(executor,
                              lambda: read_radio() and cmds[-1].twist.linear.x == 0.0, 2.0)
        finally:
            code = proc.stop()
            os.close(master)
            os.close(slave)
    assert code == 0, proc.stderr
    saved = json.loads((tmp_path / 'shore.key.timestamps').read_text())
    assert saved['timestamp'] >= signing_timestamp(time.time() - 60.0)
    assert [2, 255, 190] in [s[:3] for s in saved['streams']]
