"""Fault matrix, control rows (README "Failsafes"): drive_controller_node and
mode_manager_node as real processes, the probe playing every sensor and the planner.

Each test: the fault, how it is injected (the probe stops or spoils a stream), what
must happen and by when (measured from the injection to the first neutral tracks/cmd
the probe receives; printed, run with -s to see the figures).
"""
import math
import time

import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from dukw_msgs.msg import (Authority, DiffCommand, DrivetrainStatus, DriveMode, Traction,
                           WaterContact)
from dukw_msgs.srv import SetMode
from geometry_msgs.msg import TwistStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu

from dukw_common.cmd_vel import make_cmd_vel
from dukw_common.node_tools import COMMAND_QOS, SENSOR_QOS, STATE_QOS
from dukw_common.testing import NodeProcess, moving_before_neutral, ros_node, spin_until

pytestmark = pytest.mark.ros

PERIOD_S = 0.02                   # the probe's sensors and cmd_vel at 50 Hz
TIMEOUT_S = 0.5                   # cmd_timeout_s, imu_timeout_s, traction_timeout_s (config)
SLACK_S = 0.15                    # one probe period, a controller step and delivery


class Rig:
    """Feeds every input the two nodes need; records tracks/cmd, drive_mode, diagnostics."""

    STREAMS = ('imu', 'odometry', 'cmd_vel', 'sensors')

    def __init__(self, node, executor):
        self.node, self.executor = node, executor
        kinds = (('imu/data', Imu, SENSOR_QOS), ('odometry/filtered', Odometry, SENSOR_QOS),
                 ('cmd_vel', TwistStamped, COMMAND_QOS),
                 ('water/contact', WaterContact, SENSOR_QOS), ('traction', Traction, SENSOR_QOS),
                 ('tracks/status', DrivetrainStatus, SENSOR_QOS),
                 ('authority', Authority, STATE_QOS))
        self.pubs = {topic: node.create_publisher(kind, topic, qos) for topic, kind, qos in kinds}
        self.tracks, self.modes, self.diag = [], [], []
        node.create_subscription(DiffCommand, 'tracks/cmd',
                                 lambda m: self.tracks.append((time.monotonic(), m)),
                                 COMMAND_QOS)
        node.create_subscription(DriveMode, 'drive_mode', self.modes.append, STATE_QOS)
        node.create_subscription(DiagnosticArray, '/diagnostics', self.diag.append, COMMAND_QOS)
        self.on = dict.fromkeys(self.STREAMS, True)
        self.cmd = 1.0
        self.set_mode = node.create_client(SetMode, 'set_mode')
        self.authority(Authority.HOLDER_COMPUTER)
        node.create_timer(PERIOD_S, self.tick)

    def authority(self, holder):
        self.pubs['authority'].publish(Authority(
            holder=holder, reason=Authority.REASON_RC_SWITCH, rc_link_ok=True,
            outputs_neutral=holder != Authority.HOLDER_COMPUTER, detail='probe'))

    def tick(self):
        now = self.node.get_clock().now().to_msg()
        if self.on['imu']:
            imu = Imu()
            imu.header.stamp, imu.orientation.w = now, 1.0
            self.pubs['imu/data'].publish(imu)
        if self.on['odometry']:
            odom = Odometry()
            odom.header.stamp, odom.pose.pose.orientation.w = now, 1.0
            self.pubs['odometry/filtered'].publish(odom)
        if self.on['sensors']:
            self.pubs['water/contact'].publish(WaterContact())
            self.pubs['traction'].publish(Traction(weight_on_tracks_fraction=1.0))
            status = DrivetrainStatus(drive=DrivetrainStatus.DRIVE_TRACKS, connected=True)
            status.port.current_a = status.stbd.current_a = 10.0
            status.port.force_n = status.stbd.force_n = 200.0
            self.pubs['tracks/status'].publish(status)
        if self.on['cmd_vel']:
            now_s = self.node.get_clock().now().nanoseconds * 1e-9
            self.pubs['cmd_vel'].publish(make_cmd_vel(True, self.cmd, 0.0, now_s))

    def spin(self, predicate, timeout_s=10.0):
        return spin_until(self.executor, predicate, timeout_s)

    def moving(self):
        return bool(self.tracks) and self.tracks[-1][1].stbd_pct > 5.0

    def neutral(self):
        return bool(self.tracks) and self.tracks[-1][1].stbd_pct == 0.0

    def drive(self):
        """Every stream on, driving straight; returns once the tracks turn."""
        self.on = dict.fromkeys(self.STREAMS, True)
        self.cmd = 1.0
        assert self.spin(lambda: self.modes and self.modes[-1].mode == DriveMode.LAND, 30)
        assert self.spin(self.moving, 30), 'the rig never drove'

    def reaction_s(self, since):
        """Seconds from ``since`` to the first neutral tracks/cmd after it."""
        assert self.spin(lambda: any(t > since and m.stbd_pct == 0.0 for t, m in self.tracks))
        return next(t for t, m in self.tracks if t > since and m.stbd_pct == 0.0) - since

    def call_set_mode(self, mode):
        """Force ``mode``, or back to automatic with None."""
        request = SetMode.Request(automatic=True) if mode is None else \
            SetMode.Request(mode=mode, automatic=False)
        future = self.set_mode.call_async(request)
        assert self.spin(future.done)
        return future.result()

    def error_from(self, node_name):
        return [s for a in self.diag for s in a.status
                if s.name.startswith(node_name) and s.level == DiagnosticStatus.ERROR]


@pytest.fixture(scope='module')
def rig():
    with ros_node('fault_probe') as (node, executor):
        rig = Rig(node, executor)
        with NodeProcess('dukw_control', 'mode_manager_node') as modes, \
                NodeProcess('dukw_control', 'drive_controller_node') as ctrl:
            assert rig.set_mode.wait_for_service(timeout_sec=60.0), modes.stderr
            rig.drive()
            yield rig
            assert modes.alive() and ctrl.alive(), (modes.stderr, ctrl.stderr)


def test_cmd_vel_loss_stops_the_tracks_within_the_timeout(rig):
    rig.drive()
    rig.on['cmd_vel'] = False
    reaction = rig.reaction_s(time.monotonic())
    print(f'cmd_vel loss -> neutral tracks: {reaction:.3f} s')
    assert reaction <= TIMEOUT_S + SLACK_S


def test_dead_imu_stops_the_tracks_and_is_a_safe_stop_that_no_forcing_lifts(rig):
    rig.drive()
    rig.on['imu'] = False                     # odometry keeps coming, as from the EKF
    reaction = rig.reaction_s(time.monotonic())
    print(f'IMU silent -> neutral tracks: {reaction:.3f} s')
    assert reaction <= TIMEOUT_S + SLACK_S
    assert rig.spin(lambda: rig.modes[-1].mode == DriveMode.SAFE_STOP, 2.0)
    assert 'imu stale' in rig.modes[-1].reason
    for mode in (DriveMode.LAND, DriveMode.WATER):
        result = rig.call_set_mode(mode)
        assert not result.success and 'imu stale' in result.message
    rig.spin(lambda: False, 0.3)
    assert rig.neutral() and rig.modes[-1].mode == DriveMode.SAFE_STOP


def test_after_a_safe_stop_only_a_fresh_cmd_vel_drives(rig):
    rig.drive()
    rig.on['cmd_vel'] = False                  # the last request, still within its timeout,
    assert rig.call_set_mode(DriveMode.SAFE_STOP).success   # when a short stop comes
    assert rig.spin(lambda: rig.modes[-1].mode == DriveMode.SAFE_STOP, 2.0)
    assert rig.call_set_mode(None).success     # back to automatic: LAND
    assert rig.spin(lambda: rig.modes[-1].mode == DriveMode.LAND, 2.0)
    count = len(rig.tracks)
    rig.spin(lambda: False, TIMEOUT_S)
    after = [m.stbd_pct for _, m in rig.tracks[count:]]
    assert after and all(p == 0.0 for p in after), 'drove on a request older than the stop'
    rig.on['cmd_vel'] = True
    assert rig.spin(rig.moving, 5.0)


def test_silent_estimator_stops_the_tracks(rig):
    rig.drive()
    rig.on['odometry'] = False                # killed EKF: no odometry/filtered (pitch)
    reaction = rig.reaction_s(time.monotonic())
    print(f'estimator silent -> neutral tracks: {reaction:.3f} s')
    assert reaction <= TIMEOUT_S + SLACK_S


def test_rc_takeover_is_neutral_at_once(rig):
    rig.drive()
    since = time.monotonic()
    rig.authority(Authority.HOLDER_RC)
    reaction = rig.reaction_s(since)
    late = moving_before_neutral(rig.tracks, since)
    print(f'RC takeover -> neutral tracks: {reaction:.3f} s, {late} moving command(s) between')
    # at once: on the authority itself, not a timer later; counted in commands, not in wall
    # seconds a busy machine stretches (one in flight, one tick due at the same wake-up)
    assert late <= 2
    rig.authority(Authority.HOLDER_COMPUTER)


def test_nan_and_inf_cmd_vel_never_pass(rig):
    rig.drive()
    count = len(rig.tracks)
    for bad in (math.nan, math.inf, -math.inf):
        rig.cmd = bad
        rig.spin(lambda: False, 0.2)
    rig.cmd = 1.0
    sent = [m for _, m in rig.tracks[count:]]
    assert sent and all(math.isfinite(m.port_pct) and math.isfinite(m.stbd_pct) for m in sent)
    assert all(abs(m.stbd_pct) <= 100.0 for m in sent)


def test_a_second_drive_mode_publisher_stops_and_is_an_error(rig):
    rig.drive()
    stranger = rig.node.create_publisher(DriveMode, 'drive_mode', STATE_QOS)
    rig.diag.clear()
    since = time.monotonic()
    stranger.publish(DriveMode(mode=DriveMode.LAND, automatic=True, track_weight=1.0,
                               reason='spoofed'))
    try:
        reaction = rig.reaction_s(since)
        print(f'second drive_mode publisher -> neutral tracks: {reaction:.3f} s')
        assert reaction <= 1.0
        assert rig.spin(lambda: rig.error_from('drive_controller_node'), 3.0)
        assert 'drive_mode has 2 sources' in rig.error_from('drive_controller_node')[-1].message
    finally:
        rig.node.destroy_publisher(stranger)
    assert rig.spin(rig.moving, 10.0)          # the stranger gone: driving again


def test_forcing_water_on_dry_sand_is_refused(rig):
    rig.drive()
    result = rig.call_set_mode(DriveMode.WATER)
    assert not result.success and 'WATER refused' in result.message
    assert rig.modes[-1].mode == DriveMode.LAND and rig.modes[-1].automatic


def test_a_second_set_mode_client_is_refused_and_is_an_error(rig):
    rig.drive()
    stranger = rig.node.create_client(SetMode, 'set_mode')
    rig.diag.clear()
    try:
        rig.spin(lambda: False, 1.0)                   # the node discovers the stranger
        result = rig.call_set_mode(DriveMode.SAFE_STOP)   # even the safest request
        assert not result.success and 'set_mode has 2 sources' in result.message
        assert rig.spin(lambda: rig.error_from('mode_manager_node'), 3.0)
        assert rig.modes[-1].mode == DriveMode.LAND
    finally:
        rig.node.destroy_client(stranger)
    rig.spin(lambda: False, 1.0)                       # ... and that it is gone
    assert rig.call_set_mode(None).success
