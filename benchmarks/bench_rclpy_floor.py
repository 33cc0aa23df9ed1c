"""Benchmark: what one 100 Hz topic endpoint costs in rclpy on this machine (prints figures).

The stack's CPU target (issue 7: the stack without the simulator <= 25 % of one core)
has to be read against this floor: three processes (idle node, 100 Hz publisher of
nav_msgs/Odometry, subscriber with an empty callback), each on the EventsExecutor
that every node of the stack spins, measured by process CPU time.

    python benchmarks/bench_rclpy_floor.py [--seconds 10]
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import time
from figures import report as report_figure


def endpoint(role: str, seconds: float) -> None:
    """Run one role in this process and print its CPU share."""
    import rclpy
    from nav_msgs.msg import Odometry
    from rclpy.experimental import EventsExecutor
    from rclpy.node import Node

    from dukw_common.node_tools import SENSOR_QOS

    rclpy.init()
    node = Node(f'floor_{role}')
    if role == 'publisher':
        pub = node.create_publisher(Odometry, 'floor/odom', SENSOR_QOS)
        msg = Odometry()
        node.create_timer(0.01, lambda: pub.publish(msg))
    elif role == 'subscriber':
        node.create_subscription(Odometry, 'floor/odom', lambda _: None, SENSOR_QOS)
    executor = EventsExecutor()
    executor.add_node(node)
    for window, report in ((2.0, False), (seconds, True)):
        cpu0, wall0 = time.process_time(), time.monotonic()
        while time.monotonic() - wall0 < window:
            executor.spin_once(timeout_sec=0.05)
        if report:
            share = 100.0 * (time.process_time() - cpu0) / (time.monotonic() - wall0)
            print(f'  {role:<11} {share:5.1f} % of one core')
            report_figure(f'rclpy floor, {role} endpoint at 100 Hz', share, '% of a core')
    rclpy.shutdown()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--seconds', type=float, default=10.0)
    parser.add_argument('--role', choices=['idle', 'publisher', 'subscriber'])
    args = parser.parse_args()
    if args.role:
        endpoint(args.role, args.seconds)
        return
    print('rclpy EventsExecutor, nav_msgs/Odometry at 100 Hz, CPU share per process:')
    procs = [subprocess.Popen([sys.executable, __file__, '--role', role,
                               '--seconds', str(args.seconds)])
             for role in ('idle', 'publisher', 'subscriber')]
    for proc in procs:
        proc.wait(timeout=args.seconds + 60)


if __name__ == '__main__':
    main()
