"""record and play through real topics and real processes."""
import time

import pytest
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from dukw_bringup import bag_io
from dukw_bringup.record import Recorder
from dukw_common.node_tools import COMMAND_QOS, SENSOR_QOS, STATE_QOS
from dukw_common.testing import NodeProcess, ros_node, spin_until

pytestmark = pytest.mark.ros

N_COMMANDS = 60


def _command(seq: int):
    from dukw_msgs.msg import DiffCommand
    msg = DiffCommand(port_pct=float(seq), stbd_pct=-float(seq))
    msg.header.stamp.sec = seq
    return msg


def _drive_mode(reason: str):
    from dukw_msgs.msg import DriveMode
    return DriveMode(mode=DriveMode.WATER, automatic=True, prop_weight=1.0, reason=reason)


def test_recorder_in_process_catches_latched_and_late_topics(tmp_path):
    from dukw_msgs.msg import DiffCommand, DriveMode
    with ros_node('bag_test') as (node, executor):
        latched = node.create_publisher(DriveMode, 'drive_mode', STATE_QOS)
        latched.publish(_drive_mode('before the recorder'))
        commands = node.create_publisher(DiffCommand, 'tracks/cmd', COMMAND_QOS)
        recorder = Recorder(node, tmp_path / 'bag', ['drive_mode', 'tracks/cmd', 'late'],
                            rescan_period_s=0.05)
        assert spin_until(executor, lambda: commands.get_subscription_count() > 0, 10)
        for seq in range(5):
            commands.publish(_command(seq))
        late = node.create_publisher(DiffCommand, 'late', SENSOR_QOS)
        assert spin_until(executor, lambda: late.get_subscription_count() > 0, 10)
        late.publish(_command(99))
        spin_until(executor, lambda: recorder.counts.get('/late', 0) == 1
                   and recorder.counts.get('/drive_mode', 0) == 1
                   and recorder.counts.get('/tracks/cmd', 0) == 5, 10)
        recorder.close()
        recorder.close()  # idempotent
    summary = bag_io.summarize(tmp_path / 'bag')
    counts = {t.topic: t.count for t in summary.topics}
    assert counts == {'/drive_mode': 1, '/tracks/cmd': 5, '/late': 1}
    latched_flags = {t.topic: t.latched for t in summary.topics}
    assert latched_flags['/drive_mode'] and not latched_flags['/tracks/cmd']
    mode = [bag_io.deserialize(m) for m in bag_io.read_messages(tmp_path / 'bag', ['drive_mode'])]
    assert mode[0].reason == 'before the recorder'


def test_record_process_stopped_by_sigint_leaves_a_readable_bag(tmp_path):
    from dukw_msgs.msg import DiffCommand, DriveMode
    out = tmp_path / 'bag'
    with ros_node('bag_publisher') as (node, executor):
        latched = node.create_publisher(DriveMode, 'drive_mode', STATE_QOS)
        latched.publish(_drive_mode('latched'))
        commands = node.create_publisher(DiffCommand, 'tracks/cmd', COMMAND_QOS)
        recorder = NodeProcess('dukw_bringup', 'record', ['--out', str(out), '--all',
                                                          '--rescan', '0.1'])
        try:
            assert spin_until(executor, lambda: commands.get_subscription_count() > 0
                              and latched.get_subscription_count() > 0, 20), recorder.command
            for seq in range(N_COMMANDS):
                commands.publish(_command(seq))
                executor.spin_once(timeout_sec=0.001)
            assert commands.wait_for_all_acked()
            time.sleep(0.3)  # let the recorder's executor take the last ones from DDS
        finally:
            code = recorder.stop()
    assert code == 0, recorder.stderr
    assert str(out) in recorder.stdout.strip().splitlines()[-1]
    messages = list(bag_io.read_messages(out))
    stamps = [bag_io.deserialize(m).header.stamp.sec for m in messages
              if m.topic == '/tracks/cmd']
    assert stamps == list(range(N_COMMANDS))
    assert [bag_io.deserialize(m).reason for m in messages if m.topic == '/drive_mode'] == [
        'latched']
    assert [m.timestamp_ns for m in messages] == sorted(m.timestamp_ns for m in messages)


def test_record_refuses_an_existing_folder(tmp_path):
    proc = NodeProcess('dukw_bringup', 'record', ['--out', str(tmp_path), '--all'])
    assert proc.proc.wait(timeout=30) == 2
    proc.stop()
    assert 'exists already' in proc.stderr


def _write_bag(path, n_commands: int):
    store = bag_io.typestore()
    types = store.types
    with bag_io.BagWriter(path) as writer:
        mode = types['dukw_msgs/msg/DriveMode'](
            header=types['std_msgs/msg/Header'](
                stamp=types['builtin_interfaces/msg/Time'](sec=0, nanosec=0), frame_id=''),
            mode=1, automatic=True, track_weight=0.5, prop_weight=0.5, tracks_idle=False,
            reason='from the bag')
        writer.write_message('/drive_mode', 'dukw_msgs/msg/DriveMode', 1_000, mode)
        for seq in range(n_commands):
            cmd = types['dukw_msgs/msg/DiffCommand'](
                header=types['std_msgs/msg/Header'](
                    stamp=types['builtin_interfaces/msg/Time'](sec=seq, nanosec=0),
                    frame_id=''), port_pct=float(seq), stbd_pct=0.0)
            writer.write_message('/tracks/cmd', 'dukw_msgs/msg/DiffCommand',
                                 2_000 + seq * 10_000_000, cmd)


def test_play_delivers_every_message_in_order_to_another_process(tmp_path):
    from dukw_msgs.msg import DiffCommand, DriveMode
    from rosgraph_msgs.msg import Clock
    n = 200
    _write_bag(tmp_path / 'bag', n)
    received, modes, clocks = [], [], []
    keep_all = QoSProfile(history=HistoryPolicy.KEEP_ALL, depth=1,
                          reliability=ReliabilityPolicy.RELIABLE,
                          durability=DurabilityPolicy.VOLATILE)
    with ros_node('play_subscriber') as (node, executor):
        node.create_subscription(DiffCommand, 'tracks/cmd',
                                 lambda m: received.append(m.header.stamp.sec), keep_all)
        node.create_subscription(DriveMode, 'drive_mode', lambda m: modes.append(m.reason),
                                 STATE_QOS)
        node.create_subscription(Clock, '/clock', lambda m: clocks.append(
            m.clock.sec + m.clock.nanosec * 1e-9), keep_all)
        # 200 messages 10 ms apart = 2 s of bag time, at rate 4: about 0.5 s
        player = NodeProcess('dukw_bringup', 'play', [
            str(tmp_path / 'bag'), '--rate', '4', '--clock', '--wait-for-subscribers', '3',
            '--wait-for', 'tracks/cmd', 'drive_mode', 'clock', '--wait-timeout', '20'])
        try:
            spin_until(executor, lambda: len(received) == n and modes, 60)
        finally:
            # the player ends by itself once every message is acknowledged
            code = player.finish(timeout_s=30)
    assert code == 0, player.stdout + player.stderr
    assert f'published {n + 1} messages' in player.stdout
    assert received == list(range(n))
    assert modes == ['from the bag']
    # /clock carries the bag time (2 s of it at 100 Hz), never going back
    assert len(clocks) > 100 and clocks == sorted(clocks)
    assert clocks[-1] == pytest.approx(1.99, abs=0.011)


def test_play_refuses_a_missing_bag_and_unknown_topics(tmp_path):
    _write_bag(tmp_path / 'bag', 2)
    for args, text in (([str(tmp_path / 'nothing')], 'metadata.yaml'),
                       ([str(tmp_path / 'bag'), '--topics', 'nope'], 'nope')):
        proc = NodeProcess('dukw_bringup', 'play', args)
        assert proc.proc.wait(timeout=30) == 2
        proc.stop()
        assert text in proc.stderr
