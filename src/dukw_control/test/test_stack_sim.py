"""The whole stack on the simulator: sim_node, ekf_node and the two control nodes as
processes drive the vehicle from the sand into the sea on a cmd_vel of 1 m/s, sent as
Jazzy's geometry_msgs/TwistStamped stamped with the simulator's time."""
import itertools
import time

import pytest
from dukw_msgs.msg import DriveMode, SimTruth

from dukw_common.cmd_vel import cmd_vel_type, make_cmd_vel
from dukw_common.node_tools import COMMAND_QOS, SENSOR_QOS, STATE_QOS, stamp_to_s
from dukw_common.testing import NodeProcess, ros_node

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SIM_TIME = ['--ros-args', '-p', 'use_sim_time:=true']
#: How far out the run ends, m: the speed is judged over its last 4 s, well clear of the
#: surf (it floats off about 7-8 m out); ending at 12 m, the slow climb out of the last
#: grazes could still be in the window (a 0.66 m/s mean in one CI run).
OUT_M = 14.0


def test_sand_to_sea_on_a_cmd_vel_of_1_mps():
    with ros_node('stack_probe') as (node, executor):
        truths, modes = [], []
        node.create_subscription(SimTruth, 'sim/truth', truths.append, SENSOR_QOS)
        node.create_subscription(DriveMode, 'drive_mode', modes.append, STATE_QOS)
        cmd_vel = node.create_publisher(cmd_vel_type(True), 'cmd_vel', COMMAND_QOS)

        def request():                 # stamped with the latest sim time seen
            if truths:
                sim_s = stamp_to_s(truths[-1].header.stamp)
                cmd_vel.publish(make_cmd_vel(True, 1.0, 0.0, sim_s))
        node.create_timer(0.05, request)
        procs = [NodeProcess('dukw_sim', 'sim_node', ['--ros-args', '-p', 'real_time_factor:=1.0',
                                                      '-p', 'waves.model:=irregular']),
                 NodeProcess('dukw_estimation', 'ekf_node', SIM_TIME),
                 NodeProcess('dukw_control', 'mode_manager_node', SIM_TIME),
                 NodeProcess('dukw_control', 'drive_controller_node', SIM_TIME)]
        try:
            deadline = time.monotonic() + 150.0
            while time.monotonic() < deadline and not (truths and truths[-1].x_m > OUT_M):
                executor.spin_once(timeout_sec=0.05)
        finally:
            codes = [p.stop() for p in procs]
    errors = '\n'.join(p.stderr[-2000:] for p in procs)
    assert truths and truths[-1].x_m > OUT_M, errors
    assert codes == [0, 0, 0, 0], errors
    # SAFE_STOP while the EKF starts (and, on a loaded machine, when one of its messages
    # comes late) is the manager doing its job; the driving modes must come once each
    changes = [next(group) for _, group in itertools.groupby(modes, key=lambda m: m.mode)]
    why = [(m.mode, m.reason) for m in changes]
    driving = [mode for mode, _ in itertools.groupby(
        m.mode for m in changes if m.mode != DriveMode.SAFE_STOP)]
    assert driving == [DriveMode.LAND, DriveMode.TRANSITION, DriveMode.WATER], why
    assert all('stale' in r or 'waiting' in r for m, r in why if m == DriveMode.SAFE_STOP), why
    assert truths[-1].medium == SimTruth.MEDIUM_WATER
    last_s = truths[-1].header.stamp.sec
    recent = [t.surge_mps for t in truths if t.header.stamp.sec >= last_s - 4]
    assert 0.7 < sum(recent) / len(recent) < 1.3
    assert abs(truths[-1].y_m) < 2.0
