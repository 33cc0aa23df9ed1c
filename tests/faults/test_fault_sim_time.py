"""Fault matrix, clocks (README "Failsafes").

Row: `bringup sim` with the EKF on the wall clock against the simulator's stamps.
Injected: none -- the stack as `bringup` starts it (simulator + EKF, the stack file's
clock_node). Must: the EKF sees its sensors as live in /diagnostics (a sensor loss must
be visible there, so a healthy one must not read "silent: predict-only").
"""
import signal
import subprocess

import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus

from dukw_common.node_tools import COMMAND_QOS
from dukw_common.testing import executable, ros_node, spin_until

pytestmark = pytest.mark.ros

STACK = """
stack:
  name: ekf_on_sim
  clock_node: sim_node
  nodes:
    - {name: sim_node, package: dukw_sim, executable: sim_node}
    - {name: ekf_node, package: dukw_estimation, executable: ekf_node}
"""


def test_bringup_sim_gives_the_ekf_sim_time_so_its_sensors_read_live(tmp_path):
    stack = tmp_path / 'stack.yaml'
    stack.write_text(STACK)
    runner = subprocess.Popen([str(executable('dukw_bringup', 'bringup')), str(stack),
                               '--quiet'], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True)
    statuses = {}
    try:
        with ros_node('clock_probe') as (node, executor):
            def on_diag(array):
                for status in array.status:
                    if status.name.startswith('ekf_node') and status.name.endswith('imu'):
                        statuses.setdefault('imu', []).append(status)
            node.create_subscription(DiagnosticArray, '/diagnostics', on_diag, COMMAND_QOS)
            assert spin_until(executor, lambda: len(statuses.get('imu', [])) >= 3, 60.0), \
                runner.poll()
    finally:
        runner.send_signal(signal.SIGINT)
        out, err = runner.communicate(timeout=60)
    last = statuses['imu'][-1]
    assert last.level == DiagnosticStatus.OK and 'silent' not in last.message, last.message
    assert runner.returncode == 0, err
