"""Seconds from a sensor device coming back to its driver publishing again (issue 4: < 2 s).

Runs imu_gps_node and water_sensor_node in this process against the fake IMU and
fake Numato ADC of their tests (src/dukw_driver/test), unplugs the device for
--down-s seconds and replugs it --repeat times, and prints the time from replug to
the first imu/data (IMU) and water/contact (ADC). Figures only: no pass/fail. The
measuring loop is bench_driver_reconnect's.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from dukw_msgs.msg import WaterContact
from sensor_msgs.msg import Imu

from dukw_common.node_tools import parameter_overrides
from dukw_common.testing import ros_node
from dukw_driver.imu_gps_node import ImuGpsNode
from dukw_driver.water_sensor_node import WaterSensorNode

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / 'src' / 'dukw_driver' / 'test'))
from bench_driver_reconnect import report, run_case  # noqa: E402
from fake_device import FakeDevice  # noqa: E402
from test_imu_gps_node import FakeImu, dgps_stream  # noqa: E402
from test_water_sensor_node import FakeNumato, FakeSounder  # noqa: E402


def main() -> None:
    """Measure both nodes and print median and maximum replug-to-publish times."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--repeat', type=int, default=5)
    parser.add_argument('--down-s', type=float, default=1.5)
    args = parser.parse_args()
    numato = FakeNumato()
    results = []
    with tempfile.TemporaryDirectory() as tmp, ros_node('bench_sensor_reconnect') as (
            probe, executor):
        tmp = Path(tmp)
        with FakeDevice(tmp / 'imu', stream=FakeImu().stream, stream_period_s=0.02) as imu, \
                FakeDevice(tmp / 'dgps', stream=dgps_stream, stream_period_s=0.1) as dgps, \
                FakeDevice(tmp / 'adc', respond=numato.respond) as adc, \
                FakeDevice(tmp / 'sounder', stream=FakeSounder().stream) as sounder:
            for cls, ports, msg_type, topic, device in (
                    (ImuGpsNode, {'mavlink.port': imu.path, 'nmea.port': dgps.path}, Imu,
                     'imu/data', imu),
                    (WaterSensorNode, {'adc.port': adc.path, 'sounder.port': sounder.path},
                     WaterContact, 'water/contact', adc)):
                node = cls(context=probe.context, parameter_overrides=parameter_overrides(
                    {k: str(v) for k, v in ports.items()}))
                results.append(run_case(probe, executor, node,
                                        (msg_type, topic, lambda _msg: True), device, args))
    report(results, args.repeat)


if __name__ == '__main__':
    main()
