"""Fault matrix, recording (README "Failsafes").

Row: the recorder dies (kill -9) mid-run. Injected: SIGKILL to the `record` process
after 2.5 s of 50 Hz messages. Must: metadata.yaml there from the start; `replay`
and the bag readers open it (rebuilt from the MCAP) with every message older than 1 s
before the kill.
Row: `record` and offered QoS. Injected: a publisher offering deadline, lifespan and
manual liveliness. Must: the bag's metadata carries them as offered.
"""
import signal
import subprocess
import time

import pytest
from rclpy.duration import Duration
from rclpy.qos import LivelinessPolicy, QoSProfile, ReliabilityPolicy

from dukw_bringup import bag_io
from dukw_common.node_tools import COMMAND_QOS
from dukw_common.testing import NodeProcess, executable, ros_node, spin_until

pytestmark = pytest.mark.ros

RATE_HZ = 50.0
RUN_S = 2.5
FLUSH_S = bag_io.FLUSH_PERIOD_S


def _command(seq):
    from dukw_msgs.msg import DiffCommand
    msg = DiffCommand(port_pct=float(seq % 100), stbd_pct=0.0)
    msg.header.stamp.sec = seq
    return msg


def test_recorder_killed_mid_run_leaves_a_bag_that_opens(tmp_path):
    from dukw_msgs.msg import DiffCommand
    out = tmp_path / 'bag'
    with ros_node('kill_publisher') as (node, executor):
        pub = node.create_publisher(DiffCommand, 'tracks/cmd', COMMAND_QOS)
        recorder = NodeProcess('dukw_bringup', 'record', ['--out', str(out), 'tracks/cmd',
                                                          '--rescan', '0.1'])
        try:
            assert spin_until(executor, lambda: pub.get_subscription_count() > 0, 30), \
                recorder.command
            assert (out / 'metadata.yaml').is_file()          # written at the start
            sent = []
            start = time.monotonic()
            while time.monotonic() - start < RUN_S:
                pub.publish(_command(len(sent)))
                sent.append(time.monotonic())
                executor.spin_once(timeout_sec=1.0 / RATE_HZ)
            killed_at = time.monotonic()
            recorder.proc.send_signal(signal.SIGKILL)
        finally:
            recorder.stop()
    assert recorder.proc.returncode == -signal.SIGKILL
    replay = subprocess.run([str(executable('dukw_bringup', 'replay')), str(out), '--stream'],
                            capture_output=True, text=True, timeout=60)
    assert replay.returncode == 0 and 'recovered' in replay.stderr, replay.stderr
    seqs = [bag_io.deserialize(m).header.stamp.sec for m in bag_io.read_messages(out)]
    must_have = sum(1 for t in sent if t < killed_at - FLUSH_S - 0.2)   # 0.2 s delivery
    assert seqs == list(range(len(seqs))) and len(seqs) >= must_have, (len(seqs), must_have)
    assert bag_io.summarize(out).message_count == len(seqs)


def test_record_keeps_the_offered_qos(tmp_path):
    from dukw_msgs.msg import DiffCommand
    out = tmp_path / 'bag'
    offered = QoSProfile(depth=7, reliability=ReliabilityPolicy.RELIABLE,
                         deadline=Duration(seconds=0.2), lifespan=Duration(seconds=2.0),
                         liveliness=LivelinessPolicy.MANUAL_BY_TOPIC,
                         liveliness_lease_duration=Duration(seconds=1.0))
    with ros_node('qos_publisher') as (node, executor):
        pub = node.create_publisher(DiffCommand, 'props/cmd', offered)
        with NodeProcess('dukw_bringup', 'record', ['--out', str(out), 'props/cmd',
                                                    '--rescan', '0.1']) as recorder:
            assert spin_until(executor, lambda: pub.get_subscription_count() > 0, 30), \
                recorder.command
            pub.publish(_command(1))
            pub.assert_liveliness()
            spin_until(executor, lambda: False, 0.3)
    reader = bag_io._open_reader(out)
    try:
        (qos,) = reader.connections[0].ext.offered_qos_profiles
    finally:
        reader.close()
    assert (qos.deadline.sec, qos.deadline.nsec) == (0, 200_000_000)
    assert (qos.lifespan.sec, qos.lifespan.nsec) == (2, 0)
    assert qos.liveliness.name == 'MANUAL_BY_TOPIC'
    assert (qos.liveliness_lease_duration.sec, qos.liveliness_lease_duration.nsec) == (1, 0)
    assert qos.reliability.name == 'RELIABLE'
