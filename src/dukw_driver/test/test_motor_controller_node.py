"""motor_controller_node against a fake Roboteq on a pty, through real topics."""
import math

import pytest
from diagnostic_msgs.msg import DiagnosticStatus
from dukw_msgs.msg import DrivetrainStatus, MotorSide

from dukw_common.testing import NodeProcess, ros_node
from dukw_driver.motor_controller_node import MotorControllerNode
from fake_device import FakeDevice
from fake_roboteq import FakeRoboteq
from node_graph import NodeGraph

pytestmark = pytest.mark.ros


@pytest.fixture
def roboteq(tmp_path):
    emulator = FakeRoboteq()
    with FakeDevice(tmp_path / 'ttyRoboteq', respond=emulator.feed) as device:
        emulator.device = device
        yield emulator


class Graph(NodeGraph):
    """motor_controller_node (``drive``) plus a probe recording its status."""

    def __init__(self, probe, executor, port, drive):
        super().__init__(probe, executor, MotorControllerNode, port=port, drive=drive)
        self.msgs = self.record(DrivetrainStatus, f'{drive}/status')

    def connected(self):
        return bool(self.msgs) and self.msgs[-1].connected

    def spin_until(self, predicate, timeout_s=10.0):
        return super().spin_until(predicate, timeout_s)

    def level(self):
        status = self.status('controller')
        return None if status is None else status.level


@pytest.fixture
def tracks(roboteq):
    with ros_node('probe_motor_tracks') as (probe, executor):
        graph = Graph(probe, executor, str(roboteq.device.path), 'tracks')
        yield graph
        graph.close()


def test_tracks_status_from_the_controller(tracks, roboteq):
    assert tracks.spin_until(tracks.connected)
    status = tracks.msgs[-1]
    assert status.drive == DrivetrainStatus.DRIVE_TRACKS
    assert status.port.current_a == pytest.approx(12.3)
    assert status.port.force_n == pytest.approx(12.3 * 8.16)
    assert status.stbd.command_pct == pytest.approx(56.0)
    assert status.port.speed_mps == pytest.approx(1547 / 7 / 60 * math.pi * 0.1727)
    assert status.port.voltage_v == pytest.approx(24.6) and status.port.temperature_c == 41
    assert status.port.fault_flags == 0 and list(status.port.faults) == []
    roboteq.fault_flags, roboteq.motor_flags = 0b10, (0b10, 0)
    assert tracks.spin_until(lambda: tracks.msgs[-1].port.fault_flags != 0)
    port = tracks.msgs[-1].port
    assert port.fault_flags == MotorSide.FAULT_OVERVOLTAGE | MotorSide.FAULT_STALL
    assert list(port.faults) == ['overvoltage', 'stall']
    assert tracks.spin_until(lambda: tracks.level() == DiagnosticStatus.ERROR
                             and 'overvoltage' in tracks.status('controller').message)
    assert roboteq.commands == []


def test_unplug_reports_the_loss_and_replug_publishes_again(tracks, roboteq):
    assert tracks.spin_until(tracks.connected)
    roboteq.device.unplug()
    assert tracks.spin_until(lambda: not tracks.msgs[-1].connected)
    lost = tracks.msgs[-1]
    assert math.isnan(lost.port.current_a)
    assert lost.port.fault_flags & MotorSide.FAULT_COMM_TIMEOUT
    assert tracks.spin_until(lambda: tracks.level() == DiagnosticStatus.ERROR
                             and 'not connected' in tracks.status('controller').message,
                             timeout_s=10.0)
    count = len(tracks.msgs)
    tracks.spin_until(lambda: False, timeout_s=1.0)
    assert len(tracks.msgs) > count  # keeps publishing while the device is away
    roboteq.device.replug()
    # back-off is capped at 1 s (figure: benchmarks/bench_driver_reconnect.py)
    assert tracks.node.link.seconds_until_retry() <= 1.0
    assert tracks.spin_until(tracks.connected, timeout_s=10.0)
    assert tracks.node.link.reconnects == 1
    assert tracks.msgs[-1].port.current_a == pytest.approx(12.3)


def test_silent_controller_is_not_connected(tracks, roboteq):
    assert tracks.spin_until(tracks.connected)
    roboteq.device.silent = True
    assert tracks.spin_until(lambda: not tracks.msgs[-1].connected)
    roboteq.device.silent = False
    assert tracks.spin_until(tracks.connected)


def test_garbage_on_the_line_is_counted_and_survived(tracks, roboteq):
    assert tracks.spin_until(tracks.connected)
    for _ in range(5):
        roboteq.device.send(b'\x00\xffA=zz\rQQ=1\r')
    assert tracks.spin_until(lambda: tracks.node.monitor.parser.parse_errors >= 10)
    assert tracks.spin_until(tracks.connected)


def test_props_instance_publishes_props_status(roboteq):
    with ros_node('probe_motor_props') as (probe, executor):
        graph = Graph(probe, executor, str(roboteq.device.path), 'props')
        try:
            assert graph.spin_until(graph.connected)
            status = graph.msgs[-1]
            assert status.drive == DrivetrainStatus.DRIVE_PROPELLERS
            assert status.port.speed_mps == 0.0
            assert status.port.force_n == pytest.approx(133.0 * 0.60)
        finally:
            graph.close()


def test_bad_drive_parameter_is_refused_with_its_name():
    proc = NodeProcess('dukw_driver', 'motor_controller_node',
                       ['--ros-args', '-p', 'drive:=rudder'])
    proc.proc.wait(timeout=30)
    code = proc.stop()
    assert code == 2
    assert "'drive'" in proc.stderr and 'Traceback' not in proc.stderr
