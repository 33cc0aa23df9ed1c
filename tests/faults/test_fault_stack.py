"""Fault matrix, the whole simulated stack (README "Failsafes").

Row: the EKF process dies. Injected: SIGKILL to ekf_node while `bringup sim` drives the
mission. Must: the controller's tracks/cmd neutral within 0.5 s (pitch and traction
stale) and the runner stops the stack with exit 1 naming the node.

The stack runs on the simulator's /clock, so its timeouts are sim seconds: on a busy
machine the simulator runs slower than the wall and 0.5 sim seconds take longer. The
reactions are therefore measured on the messages' own stamps (the stack's clock), from
the last message the dead process sent to the first neutral one; the wall time is only
printed.
"""
import contextlib
import re
import signal
import subprocess
import time
from pathlib import Path

import pytest
from dukw_msgs.msg import Authority, DiffCommand
from nav_msgs.msg import Odometry

from dukw_common.node_tools import COMMAND_QOS, SENSOR_QOS, STATE_QOS, stamp_to_s
from dukw_common.testing import executable, ros_node, spin_until

pytestmark = [pytest.mark.ros, pytest.mark.slow]

TIMEOUT_S = 0.5                  # imu_timeout_s / traction_timeout_s (config)
SLACK_S = 0.15                   # the controller's tick and the delivery, sim seconds


def recorder(node, msg_type, topic: str, qos) -> list:
    """(wall receive time, message) of every ``topic`` message, appended as they come."""
    got = []
    node.create_subscription(msg_type, topic, lambda m: got.append((time.monotonic(), m)), qos)
    return got


@contextlib.contextmanager
def running_stack(shape: str, node: str, log_dir: Path):
    """``bringup SHAPE`` (node logs in ``log_dir``) until ``node`` has started: yields
    (runner, its pid), then stops it."""
    runner = subprocess.Popen([str(executable('dukw_bringup', 'bringup')), shape, '--quiet',
                               '--log-dir', str(log_dir)],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        pids = {}
        deadline = time.monotonic() + 60.0
        while node not in pids and time.monotonic() < deadline:
            match = re.search(r'started (\w+) \(pid (\d+)\)', runner.stdout.readline())
            if match:
                pids[match.group(1)] = int(match.group(2))
        yield runner, pids[node]
    finally:
        if runner.poll() is None:
            runner.send_signal(signal.SIGINT)
            runner.communicate(timeout=60)


def kill_while_driving(pid: int, executor, tracks: list) -> float:
    """Wait until the mission drives the tracks, SIGKILL ``pid``; the kill's time."""
    assert spin_until(executor, lambda: tracks and abs(tracks[-1][1].stbd_pct) > 5.0,
                      90.0), 'the mission never drove'
    since = time.monotonic()
    subprocess.run(['kill', '-KILL', str(pid)], check=True)
    return since


def test_killed_ekf_ends_in_neutral_and_stops_the_stack(tmp_path):
    with running_stack('sim', 'ekf_node', tmp_path) as (runner, pid):
        with ros_node('stack_probe') as (node, executor):
            tracks = recorder(node, DiffCommand, 'tracks/cmd', COMMAND_QOS)
            estimates = recorder(node, Odometry, 'odometry/filtered', SENSOR_QOS)
            since = kill_while_driving(pid, executor, tracks)

            def neutral_after():
                return [(t, m) for t, m in tracks if t > since and m.port_pct == 0.0
                        and m.stbd_pct == 0.0]
            assert spin_until(executor, neutral_after, 10.0)
            wall_t, neutral = neutral_after()[0]
        assert estimates, 'no estimate came before the kill'
        last_s = max(stamp_to_s(m.header.stamp) for _, m in estimates)
        reaction = stamp_to_s(neutral.header.stamp) - last_s
        print(f'EKF killed -> neutral tracks: {reaction:.3f} sim s after its last estimate '
              f'({wall_t - since:.3f} wall s after the kill)')
        assert 0.0 < reaction <= TIMEOUT_S + SLACK_S
        out, err = runner.communicate(timeout=60)
    assert runner.returncode == 1
    assert 'ekf_node exited unexpectedly (killed by signal 9)' in out + err
    # a staleness guard, not the controller's last word at shutdown, made the neutral: its
    # own on the pitch, or the mode manager's SAFE_STOP on the traction (tens of ms apart)
    assert re.search(r'neutral: (pitch stale|safe stop: traction stale)',
                     (tmp_path / 'drive_controller_node.log').read_text())


def test_killed_composed_chain_ends_in_switch_neutral_and_stops_the_stack(tmp_path):
    """Composed shape (the main job's): the EKF shares its process with the controller, so
    killing it kills both; no command comes any more and the servo switch goes neutral
    on its command timeout (0.5 s; `authority` says COMMAND_TIMEOUT); bringup exits 1."""
    with running_stack('sim_composed', 'control_chain', tmp_path) as (runner, pid):
        with ros_node('stack_probe') as (node, executor):
            tracks = recorder(node, DiffCommand, 'tracks/cmd', COMMAND_QOS)
            authority = recorder(node, Authority, 'authority', STATE_QOS)
            since = kill_while_driving(pid, executor, tracks)

            def timed_out():
                return [(t, m) for t, m in authority if t > since and m.outputs_neutral
                        and m.reason == Authority.REASON_COMMAND_TIMEOUT]
            assert spin_until(executor, timed_out, 10.0)
            wall_t, neutral = timed_out()[0]
        last_s = max(stamp_to_s(m.header.stamp) for _, m in tracks)
        reaction = stamp_to_s(neutral.header.stamp) - last_s
        print(f'composed chain killed -> switch neutral: {reaction:.3f} sim s after its last '
              f'command ({wall_t - since:.3f} wall s after the kill)')
        assert 0.0 < reaction <= TIMEOUT_S + SLACK_S + 0.1   # + the switch's status period
        out, err = runner.communicate(timeout=60)
    assert runner.returncode == 1
    assert 'control_chain exited unexpectedly (killed by signal 9)' in out + err
