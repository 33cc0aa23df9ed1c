"""Fault matrix, estimation row (README "Failsafes"): ekf_node as a real process.

Row: a second ``set_pose`` client (anyone on the domain could reset the pose). Must:
every call refused while it is there, an ERROR on /diagnostics, and calls accepted
again once it is gone -- the same single-source rule as the mode manager's set_mode.
"""
import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from dukw_msgs.srv import SetPose

from dukw_common.node_tools import COMMAND_QOS
from dukw_common.testing import NodeProcess, ros_node, spin_until

pytestmark = pytest.mark.ros


def test_a_second_set_pose_client_is_refused_and_is_an_error():
    with ros_node('fault_probe') as (node, executor), \
            NodeProcess('dukw_estimation', 'ekf_node') as ekf:
        diag = []
        node.create_subscription(DiagnosticArray, '/diagnostics', diag.append, COMMAND_QOS)
        operator = node.create_client(SetPose, 'set_pose')
        assert operator.wait_for_service(timeout_sec=60.0), ekf.stderr

        def call():
            future = operator.call_async(SetPose.Request(x_m=1.0, y_m=2.0, yaw_rad=0.5))
            assert spin_until(executor, future.done, 10.0)
            return future.result()

        def errors():
            return [s for a in diag for s in a.status if s.name.startswith('ekf_node')
                    and s.level == DiagnosticStatus.ERROR]

        stranger = node.create_client(SetPose, 'set_pose')
        spin_until(executor, lambda: False, 1.0)          # the node discovers the stranger
        result = call()
        assert not result.success and 'set_pose has 2 sources' in result.message
        assert spin_until(executor, errors, 3.0)
        assert 'set_pose has 2 sources' in errors()[-1].message
        node.destroy_client(stranger)
        spin_until(executor, lambda: False, 1.0)          # ... and that it is gone
        result = call()
        assert result.success, result.message
        diag.clear()
        spin_until(executor, lambda: len(diag) >= 2, 3.0)
        assert diag and not errors()
        assert ekf.alive(), ekf.stderr
