"""Fault matrix, bad configuration (README "Failsafes").

Row: a malformed or missing --params-file. Injected: the installed executable run
with it. Must: exit 2 at start-up with a message naming the file, no traceback.
Row: a runtime set_parameters call. Injected: through the node's parameter service.
Must: be refused (every parameter is read at start-up only), never reported as set.
"""
import subprocess

import pytest
from rcl_interfaces.srv import SetParameters
from rclpy.parameter import Parameter

from dukw_common.testing import NodeProcess, executable, ros_node, spin_until

pytestmark = pytest.mark.ros

NODES = [('dukw_driver', 'servo_switch_node'), ('dukw_driver', 'motor_controller_node'),
         ('dukw_driver', 'imu_gps_node'), ('dukw_driver', 'water_sensor_node'),
         ('dukw_estimation', 'ekf_node'), ('dukw_control', 'mode_manager_node'),
         ('dukw_control', 'drive_controller_node'), ('dukw_control', 'maneuver_node'),
         ('dukw_sim', 'sim_node'), ('dukw_bringup', 'mission_node'),
         ('dukw_bringup', 'record')]


@pytest.mark.parametrize('package,name', NODES)
def test_malformed_params_file_exits_2_naming_it(package, name, tmp_path):
    bad = tmp_path / 'broken.yaml'
    bad.write_text('drive_controller_node: {ros__parameters: [\n')
    proc = subprocess.run([str(executable(package, name)), '--ros-args', '--params-file',
                           str(bad)], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2, proc.stderr
    assert str(bad) in proc.stderr and 'Traceback' not in proc.stderr, proc.stderr


def test_missing_params_file_exits_2_naming_it(tmp_path):
    missing = tmp_path / 'nowhere.yaml'
    proc = subprocess.run([str(executable('dukw_control', 'mode_manager_node')), '--ros-args',
                           '--params-file', str(missing)], capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 2, proc.stderr
    assert str(missing) in proc.stderr and 'Traceback' not in proc.stderr, proc.stderr


def test_runtime_set_parameters_is_refused_not_ignored():
    with ros_node('param_probe') as (node, executor), \
            NodeProcess('dukw_control', 'mode_manager_node') as proc:
        client = node.create_client(SetParameters, '/mode_manager_node/set_parameters')
        assert client.wait_for_service(timeout_sec=30.0), proc.stderr
        request = SetParameters.Request(
            parameters=[Parameter('min_dwell_s', value=0.0).to_parameter_msg()])
        future = client.call_async(request)
        assert spin_until(executor, future.done, 10.0)
        (result,) = future.result().results
        assert not result.successful and 'read-only' in result.reason
