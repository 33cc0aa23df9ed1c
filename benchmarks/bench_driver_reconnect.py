"""Seconds from a device coming back to the driver publishing again (issue 4 asks < 2 s).

Runs servo_switch_node and motor_controller_node in this process against their
fake devices on ptys (src/dukw_driver/test), unplugs each device for --down-s
seconds and replugs it --repeat times, and prints the time from replug to the
first rc/input message (servo switch) and the first tracks/status with
connected true (motor controller). Figures only: no pass/fail.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

from dukw_msgs.msg import DrivetrainStatus, RcInput

from dukw_common.node_tools import SENSOR_QOS, parameter_overrides
from dukw_common.testing import ros_node, spin_until
from dukw_driver.motor_controller_node import MotorControllerNode
from dukw_driver.servo_switch_node import ServoSwitchNode

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / 'src' / 'dukw_driver' / 'test'))
from fake_device import FakeDevice  # noqa: E402
from fake_maestro import FakeMaestro  # noqa: E402
from fake_roboteq import FakeRoboteq  # noqa: E402


def measure(executor, device, published, repeat: int, down_s: float) -> list[float]:
    """Replug ``device`` ``repeat`` times; seconds until ``published()`` turns true each time."""
    figures = []
    for _ in range(repeat):
        device.unplug()
        spin_until(executor, lambda: False, down_s)
        published.reset()
        device.replug()
        start = time.monotonic()
        if spin_until(executor, published, timeout_s=10.0):
            figures.append(time.monotonic() - start)
    return figures


class Flag:
    """Becomes true on a matching message after ``reset()``."""

    def __init__(self, match) -> None:
        self.match = match
        self.seen = False

    def __call__(self) -> bool:
        return self.seen

    def reset(self) -> None:
        self.seen = False

    def on_message(self, msg) -> None:
        self.seen = self.seen or self.match(msg)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument('--repeat', type=int, default=5)
    parser.add_argument('--down-s', type=float, default=1.5)
    args = parser.parse_args()
    maestro, roboteq = FakeMaestro(), FakeRoboteq()
    maestro.set_lines(select_rc=False, link_ok=True)
    with tempfile.TemporaryDirectory() as tmp, ros_node('bench_reconnect') as (probe, executor):
        cases = []
        with FakeDevice(Path(tmp) / 'ttyMaestro', respond=maestro.feed) as m_dev, \
                FakeDevice(Path(tmp) / 'ttyRoboteq', respond=roboteq.feed) as r_dev:
            for cls, port, msg_type, topic, match, device in (
                    (ServoSwitchNode, m_dev.path, RcInput, 'rc/input', lambda m: True, m_dev),
                    (MotorControllerNode, r_dev.path, DrivetrainStatus, 'tracks/status',
                     lambda m: m.connected, r_dev)):
                node = cls(context=probe.context,
                           parameter_overrides=parameter_overrides({'port': str(port)}))
                cases.append(run_case(probe, executor, node, (msg_type, topic, match),
                                      device, args))
    report(cases, args.repeat)


def run_case(probe, executor, node, stream, device, args) -> tuple[str, list[float]]:
    """Measure one node's replug-to-publishing times; ``stream`` = (type, topic, match)."""
    msg_type, topic, match = stream
    name = node.get_name()
    executor.add_node(node)
    flag = Flag(match)
    probe.create_subscription(msg_type, topic, flag.on_message, SENSOR_QOS)
    spin_until(executor, flag, 10.0)
    figures = measure(executor, device, flag, args.repeat, args.down_s)
    executor.remove_node(node)
    shutdown = getattr(node, 'on_shutdown', None)
    if callable(shutdown):
        shutdown()
    node.destroy_node()
    return name, figures


def report(cases: list[tuple[str, list[float]]], repeat: int) -> None:
    """Print median and max replug-to-publishing time per node."""
    for name, figures in cases:
        if figures:
            print(f'{name}: replug -> publishing again: median {statistics.median(figures):.2f} s,'
                  f' max {max(figures):.2f} s over {len(figures)} of {repeat} replugs '
                  f'(issue 4: < 2 s)')
        else:
            print(f'{name}: never published again within 10 s')


if __name__ == '__main__':
    main()
