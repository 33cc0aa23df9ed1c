"""ekf_node on the simulator's topics: sim_node and ekf_node as processes, the estimate
checked against sim/truth (frames REP 105, datum and shore as configured)."""
import math
import time

import pytest
from dukw_msgs.msg import DiffCommand, SimTruth, Traction
from nav_msgs.msg import Odometry

from dukw_common.node_tools import COMMAND_QOS, SENSOR_QOS
from dukw_common.testing import NodeProcess, ros_node

pytestmark = [pytest.mark.ros, pytest.mark.slow]


def test_ekf_node_follows_the_simulated_vehicle_on_the_sand():
    with ros_node('ekf_sim_probe') as (node, executor):
        truths, odoms, tractions = [], [], []
        node.create_subscription(SimTruth, 'sim/truth', truths.append, SENSOR_QOS)
        node.create_subscription(Odometry, 'odometry/filtered', odoms.append, COMMAND_QOS)
        node.create_subscription(Traction, 'traction', tractions.append, COMMAND_QOS)
        tracks = node.create_publisher(DiffCommand, 'tracks/cmd', COMMAND_QOS)
        node.create_timer(0.05, lambda: tracks.publish(DiffCommand(port_pct=30.0,
                                                                   stbd_pct=30.0)))
        procs = [NodeProcess('dukw_sim', 'sim_node', ['--ros-args', '-p', 'start_at:=sand']),
                 NodeProcess('dukw_estimation', 'ekf_node',
                             ['--ros-args', '-p', 'use_sim_time:=true'])]
        try:
            deadline = time.monotonic() + 60.0
            while time.monotonic() < deadline and not (
                    truths and odoms and truths[-1].header.stamp.sec >= 8):
                executor.spin_once(timeout_sec=0.05)
        finally:
            codes = [p.stop() for p in procs]
    errors = '\n'.join(p.stderr[-2000:] for p in procs)
    assert codes == [0, 0], errors
    assert odoms and tractions, errors
    truth, odom = truths[-1], odoms[-1]
    assert truth.x_m > -1.5                   # it drove (started 2 m up the beach)
    p = odom.pose.pose.position
    assert math.hypot(p.x - truth.x_m, p.y - truth.y_m) < 1.0
    assert odom.twist.twist.linear.x == pytest.approx(truth.surge_mps, abs=0.2)
    assert tractions[-1].waterline_distance_m == pytest.approx(truth.waterline_distance_m,
                                                               abs=1.0)
    assert not math.isnan(tractions[-1].port_slip)
