"""Every dukw_msgs message type goes between two processes over DDS, unchanged."""
import subprocess
import sys
from pathlib import Path

import pytest

import dukw_msgs.msg
from dukw_common.node_tools import COMMAND_QOS
from dukw_common.testing import ros_node, sample_message, spin_until

TYPES = ['DiffCommand', 'MotorSide', 'DrivetrainStatus', 'WaterContact', 'Depth', 'RcInput',
         'Authority', 'DriveMode', 'Traction', 'SimTruth']


@pytest.mark.ros
def test_each_message_type_crosses_processes():
    script = Path(__file__).parent / 'support' / 'publish_samples.py'
    proc = subprocess.Popen([sys.executable, str(script), *TYPES])
    received = {}
    try:
        with ros_node('sample_subscriber') as (node, executor):
            for name in TYPES:
                node.create_subscription(getattr(dukw_msgs.msg, name), f'sample/{name}',
                                         lambda m, n=name: received.setdefault(n, m),
                                         COMMAND_QOS)
            spin_until(executor, lambda: len(received) == len(TYPES), timeout_s=30)
    finally:
        proc.terminate()
        proc.wait(timeout=10)
    assert sorted(received) == sorted(TYPES), f'missing: {set(TYPES) - set(received)}'
    for name in TYPES:
        expected = sample_message(getattr(dukw_msgs.msg, name))
        assert received[name] == expected, name


def test_sample_messages_are_not_defaults():
    # Guards the test above: a sample equal to a default message would prove nothing.
    for name in TYPES:
        cls = getattr(dukw_msgs.msg, name)
        assert sample_message(cls) != cls(), name
