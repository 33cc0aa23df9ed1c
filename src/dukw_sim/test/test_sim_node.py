"""sim_node through real rclpy: the installed executable, its topics, the servo-switch rule."""
import math

import pytest
from diagnostic_msgs.msg import DiagnosticArray
from dukw_msgs.msg import Authority, Depth, DiffCommand, DrivetrainStatus, RcInput, SimTruth
from dukw_msgs.srv import SetOperator
from rosgraph_msgs.msg import Clock
from tf2_msgs.msg import TFMessage

from dukw_common.node_tools import COMMAND_QOS, SENSOR_QOS, STATE_QOS, stamp_to_s
from dukw_common.testing import NodeProcess, ros_node, spin_until
from dukw_common.tf_tools import TF_QOS

pytestmark = [pytest.mark.ros, pytest.mark.slow]
#: Start-up on a loaded 2-core machine (imports, the physics core, discovery) can be slow.
STARTUP_S = 60.0

#: The topic contract (shared docs architecture.md) plus the simulator's own.
CONTRACT = {
    '/imu/data': 'sensor_msgs/msg/Imu', '/gps/fix': 'sensor_msgs/msg/NavSatFix',
    '/gps/vel': 'geometry_msgs/msg/TwistWithCovarianceStamped',
    '/water/contact': 'dukw_msgs/msg/WaterContact', '/depth': 'dukw_msgs/msg/Depth',
    '/tracks/status': 'dukw_msgs/msg/DrivetrainStatus',
    '/props/status': 'dukw_msgs/msg/DrivetrainStatus', '/rc/input': 'dukw_msgs/msg/RcInput',
    '/authority': 'dukw_msgs/msg/Authority', '/diagnostics': 'diagnostic_msgs/msg/DiagnosticArray',
    '/sim/truth': 'dukw_msgs/msg/SimTruth', '/clock': 'rosgraph_msgs/msg/Clock',
    '/tf': 'tf2_msgs/msg/TFMessage'}      # odom -> base_link_truth, the true pose
SUBSCRIBED = {'/tracks/cmd': 'dukw_msgs/msg/DiffCommand',
              '/props/cmd': 'dukw_msgs/msg/DiffCommand'}


class Probe:
    """Records the sim's last messages, sends tracks/cmd at 20 Hz, plays the operator."""

    def __init__(self, node, executor):
        self.node, self.executor = node, executor
        self.last = {}
        self.rc_commands_seen = []
        for topic, kind, qos in (('sim/truth', SimTruth, SENSOR_QOS),
                                 ('tracks/status', DrivetrainStatus, SENSOR_QOS),
                                 ('authority', Authority, STATE_QOS),
                                 ('rc/input', RcInput, SENSOR_QOS), ('depth', Depth, SENSOR_QOS),
                                 ('/clock', Clock, COMMAND_QOS),
                                 ('/diagnostics', DiagnosticArray, COMMAND_QOS)):
            node.create_subscription(kind, topic, lambda msg, t=topic: self._store(t, msg), qos)
        self.cmd_pub = node.create_publisher(DiffCommand, 'tracks/cmd', COMMAND_QOS)
        self.command = None
        node.create_timer(0.05, self._send)
        self.client = node.create_client(SetOperator, 'sim/set_operator')

    def _store(self, topic, msg):
        self.last[topic] = msg

    def _send(self):
        if self.command is not None:
            self.cmd_pub.publish(DiffCommand(port_pct=self.command[0], stbd_pct=self.command[1]))

    def until(self, predicate, timeout_s=30.0):
        return spin_until(self.executor, predicate, timeout_s)

    def get(self, topic, field=None):
        msg = self.last.get(topic)
        return msg if field is None or msg is None else field(msg)

    def operator(self, rc_selected, rc_link_ok, port=0.0, stbd=0.0):
        assert self.client.wait_for_service(timeout_sec=STARTUP_S)
        future = self.client.call_async(SetOperator.Request(
            rc_selected=rc_selected, rc_link_ok=rc_link_ok, port_pct=port, stbd_pct=stbd))
        assert self.until(future.done)
        return future.result()

    def tracks_cmd(self):
        return self.get('tracks/status', lambda m: (m.port.command_pct, m.stbd.command_pct))

    def fresh(self, topic):
        """Forget the last message on ``topic``; wait for a new one (in order on this topic
        only: a message of another topic published earlier may still arrive later)."""
        self.last.pop(topic, None)
        assert self.until(lambda: topic in self.last), f'nothing on {topic}'
        return self.last[topic]


@pytest.fixture
def sim_factory():
    procs = []

    def start(*ros_args):
        args = ['--ros-args', *[a for p in ros_args for a in ('-p', p)]] if ros_args else []
        proc = NodeProcess('dukw_sim', 'sim_node', args)
        procs.append(proc)
        return proc
    yield start
    for proc in procs:
        proc.stop()


def test_plain_executable_drives_on_sand_from_tracks_cmd_and_exits_0(sim_factory):
    proc = sim_factory()
    with ros_node('probe_drive') as (node, executor):
        probe = Probe(node, executor)
        assert probe.until(lambda: 'sim/truth' in probe.last, STARTUP_S), proc.stderr
        x0 = probe.get('sim/truth').x_m
        assert probe.get('sim/truth').medium == SimTruth.MEDIUM_LAND
        probe.command = (50.0, 50.0)
        assert probe.until(lambda: probe.get('sim/truth').x_m > x0 + 0.5)
        assert probe.until(lambda: probe.tracks_cmd() == (50.0, 50.0))

        def pulling(status):
            return (status.port.current_a > 0 and status.stbd.current_a > 0
                    and status.port.speed_mps > 0.5 and status.connected
                    and status.drive == DrivetrainStatus.DRIVE_TRACKS)
        assert probe.until(lambda: pulling(probe.get('tracks/status'))), probe.get('tracks/status')
        authority = probe.get('authority')
        assert authority.holder == Authority.HOLDER_COMPUTER and not authority.outputs_neutral
        # sim time: messages are stamped with the time /clock gives
        truth, clock = probe.fresh('sim/truth'), probe.fresh('/clock')
        assert abs(stamp_to_s(truth.header.stamp) - stamp_to_s(clock.clock)) < 1.0
        # commands stop: the switch times out to neutral
        probe.command = None
        assert probe.until(lambda: probe.tracks_cmd() == (0.0, 0.0))
        timeout = Authority.REASON_COMMAND_TIMEOUT
        assert probe.until(lambda: probe.get('authority').reason == timeout)
    code = proc.stop()
    assert code == 0, proc.stderr
    assert 'Traceback' not in proc.stderr


def test_publishes_exactly_the_drivers_topics_plus_truth_and_clock(sim_factory):
    sim_factory()
    with ros_node('probe_graph') as (node, executor):
        def graph():
            try:
                return (dict(node.get_publisher_names_and_types_by_node('sim_node', '/')),
                        dict(node.get_subscriber_names_and_types_by_node('sim_node', '/')))
            except Exception:   # NodeNameNonExistentError until discovery
                return {}, {}
        expected_pubs = {**CONTRACT, '/rosout': 'rcl_interfaces/msg/Log',
                         '/parameter_events': 'rcl_interfaces/msg/ParameterEvent'}
        assert spin_until(executor, lambda: set(graph()[0]) == set(expected_pubs),
                          STARTUP_S), graph()
        pubs, subs = graph()
        assert {t: types[0] for t, types in pubs.items()} == expected_pubs
        assert spin_until(executor, lambda: SUBSCRIBED.items() <= {
            t: v[0] for t, v in graph()[1].items()}.items(), STARTUP_S), graph()[1]


def test_operator_takeover_blocks_the_computer_and_link_loss_is_neutral(sim_factory):
    proc = sim_factory('real_time_factor:=2.0')
    with ros_node('probe_rc') as (node, executor):
        probe = Probe(node, executor)
        probe.command = (50.0, 50.0)
        assert probe.until(lambda: probe.tracks_cmd() == (50.0, 50.0), STARTUP_S), proc.stderr
        # the operator takes over, sticks at -30 %: computer commands no longer pass
        reply = probe.operator(True, True, -30.0, -30.0)
        assert reply.success, reply.message
        assert probe.until(lambda: probe.get('authority').holder == Authority.HOLDER_RC)
        assert probe.until(lambda: probe.tracks_cmd() == (-30.0, -30.0))
        assert probe.until(lambda: probe.get('rc/input', lambda rc: (
            rc.rc_selected, rc.link_ok, list(rc.channels_us))) == (True, True, [1350.0] * 4))
        for _ in range(3):
            assert probe.fresh('tracks/status').port.command_pct == -30.0
        # hand back: the computer's fresh commands pass again
        probe.operator(False, True)
        assert probe.until(lambda: probe.tracks_cmd() == (50.0, 50.0))
        # the RC link drops: neutral, whoever held authority
        probe.operator(False, False)
        assert probe.until(lambda: probe.get('authority').reason == Authority.REASON_RC_LINK_LOST)
        authority = probe.get('authority')
        assert authority.outputs_neutral and not authority.rc_link_ok
        assert probe.until(lambda: probe.tracks_cmd() == (0.0, 0.0))
        assert probe.until(lambda: probe.get('rc/input', lambda rc: (
            rc.link_ok, list(rc.channels_us))) == (False, [0.0] * 4))
        for _ in range(3):
            assert probe.fresh('tracks/status').port.command_pct == 0.0
        # a malformed operator request changes nothing
        reply = probe.operator(True, True, math.nan, 0.0)
        assert not reply.success and 'refused' in reply.message
        assert probe.fresh('authority').reason == Authority.REASON_RC_LINK_LOST


def test_nan_command_is_rejected_with_a_warning_and_nothing_passes(sim_factory):
    proc = sim_factory('real_time_factor:=2.0', 'rates.diagnostics_hz:=5.0')
    with ros_node('probe_nan') as (node, executor):
        probe = Probe(node, executor)
        probe.command = (40.0, 40.0)
        assert probe.until(lambda: probe.tracks_cmd() == (40.0, 40.0), STARTUP_S), proc.stderr
        probe.command = (math.nan, 40.0)
        for _ in range(5):
            assert probe.fresh('tracks/status').port.command_pct in (40.0, 0.0)

        def rejected():
            diag = probe.get('/diagnostics')
            values = {kv.key: kv.value for s in (diag.status if diag else []) for kv in s.values}
            return int(values.get('rejected_commands', 0))
        assert probe.until(lambda: rejected() > 0)
        # nothing passed on: the last good command times out to neutral
        assert probe.until(lambda: probe.tracks_cmd() == (0.0, 0.0))
    proc.stop()
    assert 'rejected' in proc.stderr and 'not finite' in proc.stderr


def test_starts_afloat_when_asked_and_the_sounder_reads_depth(sim_factory):
    proc = sim_factory('start_at:=afloat', 'real_time_factor:=4.0')
    with ros_node('probe_afloat') as (node, executor):
        probe = Probe(node, executor)
        assert probe.until(lambda: 'sim/truth' in probe.last and 'depth' in probe.last,
                           STARTUP_S), proc.stderr
        assert probe.get('sim/truth').medium == SimTruth.MEDIUM_WATER
        depth = probe.fresh('depth')
        assert depth.valid and depth.depth_m > 0.5


def test_a_bad_start_is_refused_with_exit_2(sim_factory):
    proc = sim_factory('start_at:=moon')
    proc.proc.wait(timeout=30)
    assert proc.stop() == 2
    assert 'start_at' in proc.stderr and 'Traceback' not in proc.stderr


def test_the_true_pose_is_on_tf_as_its_own_frame(sim_factory):
    proc = sim_factory('start_yaw_rad:=0.5')
    truths, tfs = {}, []
    with ros_node('probe_truth_tf') as (node, executor):
        node.create_subscription(SimTruth, 'sim/truth',
                                 lambda m: truths.setdefault(stamp_to_s(m.header.stamp), m),
                                 SENSOR_QOS)
        node.create_subscription(TFMessage, '/tf', tfs.append, TF_QOS)

        def matched():
            return [t for m in tfs for t in m.transforms
                    if stamp_to_s(t.header.stamp) in truths]
        assert spin_until(executor, lambda: len(matched()) >= 3, STARTUP_S), proc.stderr
    for tf in matched():
        truth = truths[stamp_to_s(tf.header.stamp)]
        assert (tf.header.frame_id, tf.child_frame_id) == ('odom', 'base_link_truth')
        p, q = tf.transform.translation, tf.transform.rotation
        assert (p.x, p.y, p.z) == pytest.approx((truth.x_m, truth.y_m, truth.z_m))
        assert 2 * math.atan2(q.z, q.w) == pytest.approx(truth.yaw_rad, abs=0.02)
        assert truth.yaw_rad == pytest.approx(0.5, abs=0.05)
