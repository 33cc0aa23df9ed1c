"""imu_gps_node against a fake IMU (pymavlink on the far side) and a fake DGPS on ptys."""
import math

import pytest
from geometry_msgs.msg import TwistWithCovarianceStamped
from pymavlink.dialects.v20 import common as mavlink
from sensor_msgs.msg import Imu, NavSatFix, NavSatStatus

from dukw_common.config import ConfigError
from dukw_common.geometry import euler_from_quaternion
from dukw_common.node_tools import SENSOR_QOS, parameter_overrides
from dukw_common.testing import NodeProcess, ros_node, spin_until
from dukw_driver.imu_gps_node import ImuGpsNode
from dukw_driver.nmea_stream import nmea_sentence
from fake_device import FakeDevice
from node_graph import NodeGraph

pytestmark = pytest.mark.ros


class FakeImu:
    """A GPS-aided IMU streaming MAVLink 2: heading north, turning to port, at rest on z."""

    def __init__(self, fix_type=3, north_cmps=150):
        self.encoder = mavlink.MAVLink(None, srcSystem=1, srcComponent=1)
        self.fix_type, self.north_cmps = fix_type, north_cmps

    def stream(self):
        msgs = [mavlink.MAVLink_scaled_imu_message(1, 0, 0, -1000, 0, 0, -200, 0, 0, 0),
                mavlink.MAVLink_attitude_message(1, 0.0, 0.0, 0.0, 0.0, 0.0, -0.2),
                mavlink.MAVLink_gps_raw_int_message(1, self.fix_type, 361836000, -757510000,
                                                    5000, 120, 200, 0, 0, 10),
                mavlink.MAVLink_global_position_int_message(1, 0, 0, 0, 0, self.north_cmps,
                                                            0, 0, 0)]
        return b''.join(m.pack(self.encoder) for m in msgs)


def dgps_stream():
    return (nmea_sentence('GPGST,120000.00,0.5,0.40,0.30,10.0,0.30,0.20,0.60')
            + nmea_sentence('GPGGA,120000.00,3611.016,N,07545.060,W,2,09,0.9,2.0,M,-35.0,M,'
                            '1.0,0042')
            + nmea_sentence('GPVTG,000.0,T,,M,2.9,N,5.4,K,D'))


class Graph(NodeGraph):
    """imu_gps_node plus a probe node subscribing to its topics."""

    def __init__(self, probe, executor, **overrides):
        super().__init__(probe, executor, ImuGpsNode, **overrides)
        self.imu = self.record(Imu, 'imu/data')
        self.fix = self.record(NavSatFix, 'gps/fix')
        self.vel = self.record(TwistWithCovarianceStamped, 'gps/vel')


@pytest.fixture
def devices(tmp_path):
    with FakeDevice(tmp_path / 'ttyImu', stream=FakeImu().stream, stream_period_s=0.02) as imu, \
            FakeDevice(tmp_path / 'ttyDgps', stream=dgps_stream, stream_period_s=0.1) as dgps:
        yield imu, dgps


@pytest.fixture
def graph(devices):
    imu, dgps = devices
    with ros_node('probe_imu_gps') as (probe, executor):
        graph = Graph(probe, executor, **{'mavlink.port': str(imu.path),
                                          'nmea.port': str(dgps.path)})
        yield graph
        graph.close()


def test_publishes_imu_fix_and_velocity_in_ros_frames(graph):
    def dgps_fix():
        return [f for f in graph.fix if f.status.status == NavSatStatus.STATUS_GBAS_FIX]
    assert graph.spin_until(lambda: graph.imu and dgps_fix() and graph.vel)
    imu = graph.imu[-1]
    assert imu.header.frame_id == 'imu_link'
    _, _, yaw = euler_from_quaternion(imu.orientation.x, imu.orientation.y, imu.orientation.z,
                                      imu.orientation.w)
    assert yaw == pytest.approx(math.pi / 2, abs=1e-6)               # heading north
    assert imu.angular_velocity.z == pytest.approx(0.2, abs=1e-6)    # turning to port
    assert imu.linear_acceleration.z == pytest.approx(9.80665, abs=1e-4)
    assert imu.linear_acceleration_covariance[0] == pytest.approx(0.010 ** 2)
    assert imu.angular_velocity_covariance[4] == pytest.approx(math.radians(0.172) ** 2)
    fix = dgps_fix()[-1]                                               # from the DGPS
    assert fix.latitude == pytest.approx(36.1836) and fix.longitude == pytest.approx(-75.751)
    assert fix.position_covariance_type == NavSatFix.COVARIANCE_TYPE_DIAGONAL_KNOWN
    assert fix.position_covariance[0] == pytest.approx(0.04)          # east: longitude error
    vel = graph.vel[-1]                                                # from the IMU's EKF
    assert vel.header.frame_id == 'gps_link'
    assert (vel.twist.twist.linear.x, vel.twist.twist.linear.y) == pytest.approx((0.0, 1.5))
    assert graph.spin_until(lambda: graph.status('mavlink') and graph.status('nmea'))
    assert graph.status('mavlink').level == b'\x00', graph.status('mavlink').message


def test_imu_without_gps_fix_gives_no_velocity_and_the_dgps_takes_over(tmp_path):
    no_fix = FakeImu(fix_type=1, north_cmps=0)           # ArduPilot without a fix: zeros
    with FakeDevice(tmp_path / 'ttyImu', stream=no_fix.stream, stream_period_s=0.02) as imu, \
            FakeDevice(tmp_path / 'ttyDgps', stream=dgps_stream, stream_period_s=0.1) as dgps, \
            ros_node('probe_no_fix') as (probe, executor):
        graph = Graph(probe, executor, **{'mavlink.port': str(imu.path),
                                          'nmea.port': str(dgps.path)})
        try:
            assert graph.spin_until(lambda: graph.vel, 20.0)
            graph.spin_until(lambda: False, 0.5)              # let the IMU stream on
            ys = {round(v.twist.twist.linear.y, 3) for v in graph.vel}
            assert ys == {1.5}, ys                        # only the DGPS's 5.4 km/h north
        finally:
            graph.close()


def test_unplugged_imu_is_an_error_and_publishes_again_after_replug(graph, devices):
    imu_dev, _ = devices
    assert graph.spin_until(lambda: graph.imu)
    imu_dev.unplug()
    assert graph.spin_until(lambda: (s := graph.status('mavlink')) is not None
                            and s.level == b'\x02' and 'not connected' in s.message)
    assert graph.fix, 'the DGPS keeps going while the IMU is away'
    imu_dev.replug()
    graph.imu.clear()
    # the back-off is capped at 1 s, so the port is tried again within 1 s of the replug
    # (wall-clock figures: benchmarks/bench_sensor_reconnect.py)
    assert graph.node.devices[0].link.seconds_until_retry() <= 1.0
    assert graph.spin_until(lambda: graph.imu, timeout_s=10.0)
    assert graph.spin_until(lambda: graph.value('mavlink', 'reconnects') == '1')


def test_garbage_on_the_line_is_counted_and_decoding_goes_on(graph, devices):
    imu_dev, dgps_dev = devices
    assert graph.spin_until(lambda: graph.imu and graph.fix)
    dgps_dev.send(b'$GPGGA,garbage*00\r\n\x00\xff\xfe')
    imu_dev.send(bytes(range(256)))

    assert graph.spin_until(lambda: int(graph.value('nmea', 'parse_errors', 0)) > 0
                            and int(graph.value('mavlink', 'parse_errors', 0)) > 0)
    graph.imu.clear()
    graph.fix.clear()
    assert graph.spin_until(lambda: graph.imu and graph.fix)


def test_missing_port_starts_and_reports_error(tmp_path):
    with ros_node('probe_imu_gps_missing') as (probe, executor):
        graph = Graph(probe, executor, **{'mavlink.port': str(tmp_path / 'none0'),
                                          'nmea.port': str(tmp_path / 'none1')})
        try:
            assert graph.spin_until(lambda: graph.status('nmea') is not None)
            assert graph.status('nmea').level == b'\x02'
            assert graph.status('mavlink').level == b'\x02'
            assert not graph.imu
        finally:
            graph.close()


@pytest.mark.parametrize('name,value', [('fix_source', 'galileo'), ('mavlink.baud', 12345),
                                        ('nmea.port', ''), ('imu_frame_id', ''),
                                        ('imu.gyro_std_dps', -1.0)])
def test_bad_parameters_are_refused_naming_them(name, value):
    with ros_node('probe_imu_gps_bad') as (probe, _):
        with pytest.raises(ConfigError, match=name.replace('.', r'\.')):
            ImuGpsNode(context=probe.context,
                       parameter_overrides=parameter_overrides({name: value}))


def test_installed_executable_publishes_from_a_fake_device_and_exits_0(devices):
    imu_dev, dgps_dev = devices
    with ros_node('probe_imu_gps_process') as (probe, executor):
        imu = []
        probe.create_subscription(Imu, 'imu/data', imu.append, SENSOR_QOS)
        proc = NodeProcess('dukw_driver', 'imu_gps_node', [
            '--ros-args', '-p', f'mavlink.port:={imu_dev.path}', '-p',
            f'nmea.port:={dgps_dev.path}'])
        try:
            assert spin_until(executor, lambda: imu, timeout_s=20), proc.stderr
        finally:
            code = proc.stop()
    assert code == 0, proc.stderr
    assert 'Traceback' not in proc.stderr
