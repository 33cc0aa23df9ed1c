"""water_sensor_node against a fake Numato ADC module and a fake Airmar DT800 on ptys."""
import math
import re
import threading

import pytest
from dukw_msgs.msg import Depth, WaterContact

from dukw_common.config import ConfigError
from dukw_common.node_tools import SENSOR_QOS, parameter_overrides
from dukw_common.testing import NodeProcess, ros_node, spin_until
from dukw_driver.nmea_stream import nmea_sentence
from dukw_driver.water_sensor_node import WaterSensorNode
from fake_device import FakeDevice
from node_graph import NodeGraph

pytestmark = pytest.mark.ros


class FakeNumato:
    """The Numato module's ASCII protocol: echo 'adc read N', then the counts and a prompt."""

    def __init__(self):
        self.counts = {0: 20, 1: 20}
        self.lock = threading.Lock()
        self._buffer = b''

    def respond(self, data):
        self._buffer += data
        out = b''
        while b'\r' in self._buffer:
            line, self._buffer = self._buffer.split(b'\r', 1)
            match = re.fullmatch(rb'adc read (\d)', line.strip())
            with self.lock:
                value = self.counts.get(int(match.group(1))) if match else None
            out += line + b'\n\r' + (b'%d\n\r' % value if value is not None else b'') + b'>'
        return out


class FakeSounder:
    """An Airmar DT800 sending DPT and MTW once per period."""

    def __init__(self):
        self.depth = '2.40'

    def stream(self):
        return nmea_sentence(f'SDDPT,{self.depth},-0.25,') + nmea_sentence('YXMTW,17.5,C')


class Graph(NodeGraph):
    """water_sensor_node plus a probe node subscribing to its topics."""

    def __init__(self, probe, executor, **overrides):
        super().__init__(probe, executor, WaterSensorNode, **overrides)
        self.contact = self.record(WaterContact, 'water/contact')
        self.depth = self.record(Depth, 'depth')


@pytest.fixture
def fakes(tmp_path):
    numato, sounder = FakeNumato(), FakeSounder()
    with FakeDevice(tmp_path / 'ttyAdc', respond=numato.respond) as adc_dev, \
            FakeDevice(tmp_path / 'ttySounder', stream=sounder.stream,
                       stream_period_s=0.1) as sounder_dev:
        yield numato, adc_dev, sounder, sounder_dev


@pytest.fixture
def graph(fakes):
    _, adc_dev, _, sounder_dev = fakes
    with ros_node('probe_water') as (probe, executor):
        graph = Graph(probe, executor, **{'adc.port': str(adc_dev.path),
                                          'sounder.port': str(sounder_dev.path)})
        yield graph
        graph.close()


def test_fore_goes_wet_after_the_debounce_and_aft_stays_dry(graph, fakes):
    numato, adc_dev, _, _ = fakes
    assert graph.spin_until(lambda: graph.contact)
    first = graph.contact[-1]
    assert not first.fore_wet and not first.aft_wet
    assert first.fore_level == pytest.approx(20 / 1023)
    assert first.header.frame_id == 'base_link'
    assert adc_dev.wait_for(lambda sent: b'adc read 0\r' in sent and b'adc read 1\r' in sent)
    with numato.lock:
        numato.counts[0] = 900
    assert graph.spin_until(lambda: graph.contact[-1].fore_wet)
    first_high = next(m for m in graph.contact if m.fore_level > 0.8)
    assert not first_high.fore_wet                 # not before the 0.2 s debounce
    assert not graph.contact[-1].aft_wet


def test_depth_with_offset_and_temperature_then_too_shallow(graph, fakes):
    _, _, sounder, _ = fakes
    assert graph.spin_until(lambda: graph.depth and not math.isnan(graph.depth[-1].water_temp_c))
    depth = graph.depth[-1]
    assert depth.valid and depth.depth_m == pytest.approx(2.40)
    assert depth.offset_m == pytest.approx(-0.25) and depth.water_temp_c == pytest.approx(17.5)
    sounder.depth = '0.42'                          # under sensors.depth_sounder_min_m = 0.5
    assert graph.spin_until(lambda: not graph.depth[-1].valid)
    assert math.isnan(graph.depth[-1].depth_m)


def test_unplugged_adc_is_an_error_and_publishes_again_after_replug(graph, fakes):
    _, adc_dev, _, _ = fakes
    assert graph.spin_until(lambda: graph.contact)
    adc_dev.unplug()
    assert graph.spin_until(lambda: (s := graph.status('adc')) is not None
                            and s.level == b'\x02' and 'not connected' in s.message)
    adc_dev.replug()
    graph.contact.clear()
    # the back-off is capped at 1 s (wall-clock figures: benchmarks/bench_sensor_reconnect.py)
    assert graph.node.adc_dev.link.seconds_until_retry() <= 1.0
    assert graph.spin_until(lambda: graph.contact, timeout_s=10.0)
    assert graph.depth, 'the sounder kept publishing while the ADC was away'


def test_silent_adc_times_out_and_garbage_from_the_sounder_is_counted(graph, fakes):
    _, adc_dev, _, sounder_dev = fakes
    assert graph.spin_until(lambda: graph.contact and graph.depth)
    adc_dev.silent = True
    sounder_dev.send(b'$SDDPT,9.9,0.0*00\r\n\xff\xfe garbage\r\n')
    assert graph.spin_until(lambda: int(graph.value('adc', 'timeouts', 0)) > 0
                            and int(graph.value('sounder', 'parse_errors', 0)) >= 2)
    assert graph.spin_until(lambda: graph.status('adc').level == b'\x02')  # stale_after_s
    adc_dev.silent = False
    graph.contact.clear()
    assert graph.spin_until(lambda: graph.contact)


def test_missing_ports_start_and_report_error(tmp_path):
    with ros_node('probe_water_missing') as (probe, executor):
        graph = Graph(probe, executor, **{'adc.port': str(tmp_path / 'none0'),
                                          'sounder.port': str(tmp_path / 'none1')})
        try:
            assert graph.spin_until(lambda: graph.status('sounder') is not None)
            assert graph.status('adc').level == b'\x02'
            assert graph.status('sounder').level == b'\x02'
        finally:
            graph.close()


@pytest.mark.parametrize('overrides,name', [
    ({'adc.aft_channel': 0}, 'adc.aft_channel'),
    ({'contact.wet_off_level': 0.9}, 'contact'),
    ({'sounder.baud': 1234}, 'sounder.baud'),
    ({'adc.port': ''}, 'adc.port'),
    ({'adc.fore_channel': 12}, 'adc.fore_channel'),
    ({'sensors.depth_sounder_min_m': -1.0}, 'sensors.depth_sounder_min_m')])
def test_bad_parameters_are_refused_naming_them(overrides, name):
    with ros_node('probe_water_bad') as (probe, _):
        with pytest.raises(ConfigError, match=re.escape(name)):
            WaterSensorNode(context=probe.context,
                            parameter_overrides=parameter_overrides(overrides))


def test_installed_executable_publishes_from_fake_devices_and_exits_0(fakes):
    _, adc_dev, _, sounder_dev = fakes
    with ros_node('probe_water_process') as (probe, executor):
        contact, depth = [], []
        probe.create_subscription(WaterContact, 'water/contact', contact.append, SENSOR_QOS)
        probe.create_subscription(Depth, 'depth', depth.append, SENSOR_QOS)
        proc = NodeProcess('dukw_driver', 'water_sensor_node', [
            '--ros-args', '-p', f'adc.port:={adc_dev.path}', '-p',
            f'sounder.port:={sounder_dev.path}'])
        try:
            assert spin_until(executor, lambda: contact and depth, timeout_s=20), proc.stderr
        finally:
            code = proc.stop()
    assert code == 0, proc.stderr
    assert 'Traceback' not in proc.stderr
