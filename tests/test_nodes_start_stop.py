"""Each node starts from its installed executable, joins the graph and exits 0 on SIGINT."""
import pytest

from dukw_common.testing import NodeProcess, ros_node, spin_until

NODES = [('dukw_driver', 'servo_switch_node'), ('dukw_driver', 'motor_controller_node'),
         ('dukw_driver', 'imu_gps_node'), ('dukw_driver', 'water_sensor_node'),
         ('dukw_estimation', 'ekf_node'), ('dukw_control', 'mode_manager_node'),
         ('dukw_control', 'drive_controller_node'), ('dukw_sim', 'sim_node'),
         ('dukw_bringup', 'robot_state_node'), ('dukw_bringup', 'live_view_node')]


@pytest.mark.ros
@pytest.mark.parametrize('package,name', NODES)
def test_node_starts_and_stops_cleanly(package, name):
    with ros_node(f'probe_{name}') as (probe, executor):
        proc = NodeProcess(package, name)
        try:
            seen = spin_until(executor, lambda: name in probe.get_node_names(), timeout_s=60)
            alive = proc.alive()
        finally:
            code = proc.stop()
    assert seen, f'{name} never joined the graph; stderr:\n{proc.stderr}'
    assert alive
    assert code == 0, f'exit {code}; stderr:\n{proc.stderr}'
    assert 'Traceback' not in proc.stderr, proc.stderr


@pytest.mark.ros
def test_bad_parameter_file_is_refused_with_a_clear_message(tmp_path):
    bad = tmp_path / 'bad.yaml'
    bad.write_text('sim_node: [this is: not a parameter file\n')
    proc = NodeProcess('dukw_sim', 'sim_node', env={'DUKW_CONFIG': str(bad)})
    proc.proc.wait(timeout=30)
    code = proc.stop()
    assert code == 2
    assert 'not valid YAML' in proc.stderr
    assert 'Traceback' not in proc.stderr
