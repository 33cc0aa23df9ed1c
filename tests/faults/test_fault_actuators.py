"""Fault matrix, actuator rows (README "Failsafes"): sim_node as a real process stands in
for the servo switch (the same CommandGate rule), the probe or a commander process
(tests/support/track_commander.py) commands.

Each test: the fault, how it is injected, what must happen and by when (wall time from
the injection to the simulator's first neutral track command; printed, -s shows it).
"""
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from dukw_msgs.msg import Authority, DiffCommand, DrivetrainStatus
from dukw_msgs.srv import SetOperator

from dukw_common.node_tools import COMMAND_QOS, SENSOR_QOS, STATE_QOS
from dukw_common.testing import NodeProcess, ros_node, spin_until

pytestmark = pytest.mark.ros

COMMANDER = Path(__file__).resolve().parents[1] / 'support' / 'track_commander.py'
COMMAND_TIMEOUT_S = 0.5          # sim_node / servo_switch_node command_timeout_s (config)
STATUS_PERIOD_S = 0.05           # tracks/status at 20 Hz: a neutral is seen this much later


class Probe:
    """Records the simulator's track commands, authority and diagnostics."""

    def __init__(self, node, executor):
        self.node, self.executor = node, executor
        self.status, self.authority, self.diag = [], [], []
        node.create_subscription(DrivetrainStatus, 'tracks/status',
                                 lambda m: self.status.append((time.monotonic(), m)),
                                 SENSOR_QOS)
        node.create_subscription(Authority, 'authority', self.authority.append, STATE_QOS)
        node.create_subscription(DiagnosticArray, '/diagnostics', self.diag.append, COMMAND_QOS)
        self.operator = node.create_client(SetOperator, 'sim/set_operator')

    def spin(self, predicate, timeout_s=10.0):
        return spin_until(self.executor, predicate, timeout_s)

    def command_pct(self):
        if not self.status:
            return None
        msg = self.status[-1][1]
        return (msg.port.command_pct, msg.stbd.command_pct)

    def reaction_s(self, since):
        """Seconds from ``since`` to the first neutral track command after it."""
        def neutral_after():
            return [t for t, m in self.status if t > since
                    and (m.port.command_pct, m.stbd.command_pct) == (0.0, 0.0)]
        assert self.spin(neutral_after, 10.0), self.command_pct()
        return neutral_after()[0] - since

    def set_operator(self, rc_selected, rc_link_ok):
        assert self.operator.wait_for_service(timeout_sec=30.0)
        future = self.operator.call_async(SetOperator.Request(rc_selected=rc_selected,
                                                              rc_link_ok=rc_link_ok))
        assert self.spin(future.done)
        return future.result()


@pytest.fixture(scope='module')
def probe():
    with ros_node('actuator_probe') as (node, executor), \
            NodeProcess('dukw_sim', 'sim_node') as sim:
        probe = Probe(node, executor)
        assert probe.spin(lambda: probe.status, 60.0), sim.stderr
        yield probe


def _commanding(probe, pub, pct):
    timer = probe.node.create_timer(
        0.02, lambda: pub.publish(DiffCommand(port_pct=pct[0], stbd_pct=pct[1])))
    assert probe.spin(lambda: probe.command_pct() == pct, 10.0), probe.command_pct()
    return timer


def test_a_second_tracks_cmd_publisher_neutralises_and_is_an_error(probe):
    own = probe.node.create_publisher(DiffCommand, 'tracks/cmd', COMMAND_QOS)
    timer = _commanding(probe, own, (40.0, 40.0))
    stranger = probe.node.create_publisher(DiffCommand, 'tracks/cmd', COMMAND_QOS)
    probe.diag.clear()
    since = time.monotonic()
    stranger.publish(DiffCommand(port_pct=100.0, stbd_pct=-100.0))
    try:
        reaction = probe.reaction_s(since)
        print(f'second tracks/cmd publisher -> neutral: {reaction:.3f} s')
        assert reaction <= 1.0
        assert not any(t > since and m.stbd.command_pct < 0.0 for t, m in probe.status)
        assert probe.spin(lambda: probe.authority[-1].outputs_neutral
                          and 'second command source' in probe.authority[-1].detail, 3.0)

        def error():
            return [s for a in probe.diag for s in a.status
                    if s.level == DiagnosticStatus.ERROR and 'second' in s.message]
        assert probe.spin(error, 3.0)
    finally:
        probe.node.destroy_publisher(stranger)
    assert probe.spin(lambda: probe.command_pct() == (40.0, 40.0), 10.0)   # one source again
    probe.node.destroy_timer(timer)
    probe.node.destroy_publisher(own)
    assert probe.spin(lambda: probe.command_pct() == (0.0, 0.0), 5.0)


@pytest.mark.parametrize('rc_selected,rc_link_ok,name', [
    (True, True, 'RC takeover'), (False, False, 'RC link loss')])
def test_rc_takeover_and_link_loss_are_neutral_at_once(probe, rc_selected, rc_link_ok, name):
    own = probe.node.create_publisher(DiffCommand, 'tracks/cmd', COMMAND_QOS)
    timer = _commanding(probe, own, (30.0, 30.0))
    try:
        since = time.monotonic()
        assert probe.set_operator(rc_selected, rc_link_ok).success
        reaction = probe.reaction_s(since)
        print(f'{name} -> neutral: {reaction:.3f} s')
        assert reaction <= STATUS_PERIOD_S + 0.1
        assert probe.authority[-1].outputs_neutral or probe.authority[-1].holder == \
            Authority.HOLDER_RC
    finally:
        assert probe.set_operator(False, True).success
        probe.node.destroy_timer(timer)
        probe.node.destroy_publisher(own)


def test_a_killed_commander_ends_in_neutral_by_the_command_timeout(probe):
    # last in this module: a SIGKILLed publisher stays in the DDS graph until its lease
    # runs out (about 20 s), and a second commander is refused meanwhile
    commander = subprocess.Popen([sys.executable, str(COMMANDER), '44.0', '100.0'],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert probe.spin(lambda: probe.command_pct() == (44.0, 100.0), 60.0), \
            probe.authority[-1]
        since = time.monotonic()
        commander.send_signal(signal.SIGKILL)
        reaction = probe.reaction_s(since)
    finally:
        commander.kill()
        commander.communicate(timeout=30)
    print(f'commander killed -> neutral: {reaction:.3f} s')
    assert reaction <= COMMAND_TIMEOUT_S + STATUS_PERIOD_S + 0.1
    assert probe.spin(lambda: probe.authority[-1].reason == Authority.REASON_COMMAND_TIMEOUT)
