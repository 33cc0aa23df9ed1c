"""Publish one sample of each given dukw_msgs type on `sample/<Type>` until killed.

Run as its own process by tests/test_messages_cross_process.py.
"""
import sys

import rclpy
from rclpy.node import Node

import dukw_msgs.msg
from dukw_common.node_tools import COMMAND_QOS
from dukw_common.testing import sample_message


def main() -> None:
    rclpy.init()
    node = Node('sample_publisher')
    pubs = []
    for name in sys.argv[1:]:
        cls = getattr(dukw_msgs.msg, name)
        pubs.append((node.create_publisher(cls, f'sample/{name}', COMMAND_QOS),
                     sample_message(cls)))
    node.create_timer(0.1, lambda: [pub.publish(msg) for pub, msg in pubs])
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    finally:
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
