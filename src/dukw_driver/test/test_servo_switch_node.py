"""servo_switch_node against a fake Maestro on a pty, through real topics."""
import math

import pytest
from diagnostic_msgs.msg import DiagnosticStatus
from dukw_msgs.msg import Authority, DiffCommand, RcInput

from dukw_common.node_tools import COMMAND_QOS, STATE_QOS
from dukw_common.testing import NodeProcess, ros_node, spin_until
from dukw_driver.servo_switch_node import ServoSwitchNode
from fake_device import FakeDevice
from fake_maestro import FakeMaestro
from node_graph import NodeGraph

pytestmark = pytest.mark.ros
NEUTRAL_US = [1500.0] * 4


@pytest.fixture
def maestro(tmp_path):
    emulator = FakeMaestro()
    emulator.set_lines(select_rc=False, link_ok=True)
    with FakeDevice(tmp_path / 'ttyMaestro', respond=emulator.feed) as device:
        emulator.device = device
        yield emulator


class Graph(NodeGraph):
    """servo_switch_node plus a probe recording authority and rc/input, publishing commands."""

    def __init__(self, probe, executor, port):
        super().__init__(probe, executor, ServoSwitchNode, port=port, rate_hz=50.0)
        self.authority = self.record(Authority, 'authority', STATE_QOS)
        self.rc = self.record(RcInput, 'rc/input')
        self.tracks = probe.create_publisher(DiffCommand, 'tracks/cmd', COMMAND_QOS)

    def spin_until(self, predicate, timeout_s=10.0, command=None):
        """Spin; publish ``command`` (port, stbd) on tracks/cmd every spin if given."""
        def check():
            if command is not None:
                self.tracks.publish(DiffCommand(port_pct=command[0], stbd_pct=command[1]))
            return predicate()
        return super().spin_until(check, timeout_s)

    def holder_is(self, holder, reason=None):
        last = self.authority[-1] if self.authority else None
        return last is not None and last.holder == holder and (
            reason is None or last.reason == reason)

    def level(self):
        status = self.status('maestro')
        return None if status is None else status.level


@pytest.fixture
def graph(maestro):
    with ros_node('probe_servo_switch') as (probe, executor):
        graph = Graph(probe, executor, str(maestro.device.path))
        yield graph
        graph.close()


def outputs_us(maestro):
    return [maestro.target_us(c) for c in range(4)]


def test_forwards_computer_commands_then_operator_takes_over(graph, maestro):
    assert graph.spin_until(lambda: graph.holder_is(Authority.HOLDER_COMPUTER))
    assert graph.spin_until(lambda: maestro.target_us(0) == 1800.0, command=(60.0, 56.0))
    assert outputs_us(maestro) == [1800.0, 1780.0, 1500.0, 1500.0]
    maestro.set_lines(select_rc=True, link_ok=True)
    assert graph.spin_until(lambda: graph.holder_is(Authority.HOLDER_RC), command=(60.0, 56.0))
    # the device reaches neutral (its reader thread may lag the node on a loaded machine) and
    # stays there: commands keep coming, none is forwarded while the operator holds authority
    assert graph.spin_until(lambda: outputs_us(maestro) == NEUTRAL_US, timeout_s=2.0,
                            command=(60.0, 56.0))
    graph.spin_until(lambda: False, timeout_s=0.3, command=(60.0, 56.0))
    assert outputs_us(maestro) == NEUTRAL_US
    assert graph.rc and graph.rc[-1].rc_selected and graph.rc[-1].link_ok
    assert len(graph.rc[-1].channels_us) == 4
    assert graph.spin_until(lambda: graph.level() == DiagnosticStatus.OK, timeout_s=10.0)
    assert float(graph.value('maestro', 'message_rate_hz')) > 0


def test_rc_link_loss_is_neutral(graph, maestro):
    assert graph.spin_until(lambda: maestro.target_us(1) == 1780.0, command=(60.0, 56.0))
    maestro.set_lines(select_rc=False, link_ok=False)
    assert graph.spin_until(lambda: graph.holder_is(Authority.HOLDER_NONE,
                                                    Authority.REASON_RC_LINK_LOST),
                            command=(60.0, 56.0))
    graph.spin_until(lambda: False, timeout_s=0.2, command=(60.0, 56.0))
    assert outputs_us(maestro) == NEUTRAL_US
    assert not graph.authority[-1].rc_link_ok and graph.authority[-1].outputs_neutral


def test_command_timeout_is_neutral(graph, maestro):
    assert graph.spin_until(lambda: maestro.target_us(0) == 1800.0, command=(60.0, 56.0))
    assert graph.spin_until(lambda: graph.holder_is(Authority.HOLDER_COMPUTER,
                                                    Authority.REASON_COMMAND_TIMEOUT))
    assert graph.spin_until(lambda: outputs_us(maestro) == NEUTRAL_US, timeout_s=5.0)
    assert graph.authority[-1].outputs_neutral


def test_nan_and_out_of_range_commands_are_refused(graph, maestro):
    assert graph.spin_until(lambda: graph.holder_is(Authority.HOLDER_COMPUTER))
    graph.spin_until(lambda: False, timeout_s=0.3, command=(math.nan, 10.0))
    graph.spin_until(lambda: False, timeout_s=0.3, command=(150.0, 10.0))
    assert outputs_us(maestro) == NEUTRAL_US
    assert graph.node.rejected > 0


def test_unplug_reports_the_loss_and_replug_publishes_again(graph, maestro):
    assert graph.spin_until(lambda: graph.holder_is(Authority.HOLDER_COMPUTER))
    maestro.device.unplug()
    assert graph.spin_until(lambda: graph.holder_is(Authority.HOLDER_NONE,
                                                    Authority.REASON_DEVICE_LOST))
    assert graph.spin_until(lambda: graph.level() == DiagnosticStatus.ERROR, timeout_s=10.0)
    assert graph.value('maestro', 'connected') == 'False'
    assert not graph.node.link.connected and graph.node.link.errors > 1
    seen = len(graph.rc)
    maestro.device.replug()
    # back-off is capped at 1 s, so the node tries the port again within 1 s of the replug
    # (the wall-clock figure, ~1 s, is in benchmarks/bench_driver_reconnect.py)
    assert graph.node.link.seconds_until_retry() <= 1.0
    assert graph.spin_until(lambda: len(graph.rc) > seen, timeout_s=10.0)
    assert graph.spin_until(lambda: graph.holder_is(Authority.HOLDER_COMPUTER))
    assert graph.node.link.reconnects == 1
    assert graph.spin_until(lambda: graph.value('maestro', 'reconnects') == '1', timeout_s=10.0)
    assert graph.spin_until(lambda: maestro.target_us(0) == 1800.0, command=(60.0, 56.0))


def test_on_shutdown_writes_neutral(graph, maestro):
    assert graph.spin_until(lambda: maestro.target_us(0) == 1800.0, command=(60.0, 56.0))
    graph.node.on_shutdown()
    assert maestro.device.wait_for(lambda _: outputs_us(maestro) == NEUTRAL_US, timeout_s=5.0)
    assert graph.spin_until(lambda: any(a.reason == Authority.REASON_SHUTDOWN
                                        and a.outputs_neutral for a in graph.authority))


def test_sigint_writes_neutral_to_the_device_as_the_last_thing(maestro):
    with ros_node('probe_servo_process') as (probe, executor):
        tracks = probe.create_publisher(DiffCommand, 'tracks/cmd', COMMAND_QOS)
        proc = NodeProcess('dukw_driver', 'servo_switch_node',
                           ['--ros-args', '-p', f'port:={maestro.device.path}'])
        try:
            moving = spin_until(executor, lambda: tracks.publish(
                DiffCommand(port_pct=-40.0, stbd_pct=-40.0)) or maestro.target_us(0) == 1300.0,
                timeout_s=20)
        finally:
            code = proc.stop()
    assert moving, proc.stderr
    assert code == 0, proc.stderr
    assert 'Traceback' not in proc.stderr
    assert outputs_us(maestro) == NEUTRAL_US
    # the last bytes the node wrote are Set Target neutral for the four outputs
    neutral = b''.join(bytes((0x84, c, 6000 & 0x7F, 6000 >> 7)) for c in range(4))
    assert maestro.device.take_received().endswith(neutral)


def test_bad_port_parameter_is_refused_with_its_name():
    proc = NodeProcess('dukw_driver', 'servo_switch_node', ['--ros-args', '-p', 'baud:=1234'])
    proc.proc.wait(timeout=30)
    code = proc.stop()
    assert code == 2
    assert "'baud'" in proc.stderr and 'Traceback' not in proc.stderr


def test_maestro_error_register_is_a_warning_on_diagnostics(graph, maestro):
    assert graph.spin_until(lambda: graph.holder_is(Authority.HOLDER_COMPUTER))
    seen = len(graph.diag)
    with maestro.lock:
        maestro.errors = 1 << 5  # serial timeout: the Maestro went to its home positions

    def warned():                # the device clears its register when read: the WARN is in
        return [s for array in graph.diag[seen:] for s in array.status   # one report, and
                if s.name.endswith('maestro') and s.level == DiagnosticStatus.WARN  # a later
                and 'serial_timeout' in s.message]                       # one may follow it
    assert graph.spin_until(lambda: bool(warned()))
    assert {kv.key: kv.value for kv in warned()[0].values}['device_errors'] == 'serial_timeout'
