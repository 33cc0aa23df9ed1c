"""Publish tracks/cmd (port, stbd from argv, %) at 50 Hz until killed: a stand-in for
the controller process in the fault tests (tests/faults/test_fault_actuators.py)."""
import sys

import rclpy
from dukw_msgs.msg import DiffCommand
from rclpy.node import Node

from dukw_common.node_tools import COMMAND_QOS


def main() -> None:
    rclpy.init()
    node = Node('track_commander')
    pub = node.create_publisher(DiffCommand, 'tracks/cmd', COMMAND_QOS)
    msg = DiffCommand(port_pct=float(sys.argv[1]), stbd_pct=float(sys.argv[2]))
    node.create_timer(0.02, lambda: pub.publish(msg))
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    finally:
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
