"""The install tree is what `ros2 run` resolves on a full ROS 2 install."""
import os
from pathlib import Path

import pytest
from ament_index_python.packages import get_package_prefix, get_package_share_directory

NODES = {
    'dukw_driver': ['servo_switch_node', 'motor_controller_node', 'imu_gps_node',
                    'water_sensor_node', 'shore_link_node'],
    'dukw_estimation': ['ekf_node'],
    'dukw_control': ['mode_manager_node', 'drive_controller_node'],
    'dukw_sim': ['sim_node'],
    'dukw_bringup': ['mission_node', 'robot_state_node', 'live_view_node', 'compose'],
}
WORKSPACE = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize('package', [*NODES, 'dukw_msgs', 'dukw_common', 'dukw_model'])
def test_package_in_ament_index_of_the_merged_install(package):
    prefix = Path(get_package_prefix(package))
    assert prefix == WORKSPACE / 'install'
    marker = prefix / 'share/ament_index/resource_index/packages' / package
    assert marker.is_file()
    assert (Path(get_package_share_directory(package)) / 'package.xml').is_file()


@pytest.mark.parametrize('package,name', [(p, n) for p, ns in NODES.items() for n in ns])
def test_node_executable_where_ros2_run_looks(package, name):
    exe = WORKSPACE / 'install/lib' / package / name
    assert exe.is_file(), exe
    assert os.access(exe, os.X_OK)


def test_config_installed_with_the_stack():
    installed = Path(get_package_share_directory('dukw_common')) / 'config/dukw.yaml'
    assert installed.read_text() == (WORKSPACE / 'config/dukw.yaml').read_text()


def test_paper_reference_installed_with_the_stack():
    installed = Path(get_package_share_directory('dukw_common')) / 'config/reference/paper.yaml'
    assert installed.read_text() == (WORKSPACE / 'config/reference/paper.yaml').read_text()
    assert (WORKSPACE / 'install/lib/dukw_sim/validate').is_file()


def test_generated_interfaces_import():
    from dukw_msgs import msg, srv
    for name in ['DiffCommand', 'MotorSide', 'DrivetrainStatus', 'WaterContact', 'Depth',
                 'RcInput', 'Authority', 'DriveMode', 'Traction', 'SimTruth']:
        assert hasattr(msg, name), name
    for name in ['SetMode', 'SetPose', 'SetOperator']:
        assert hasattr(srv, name), name


def test_tf2_msgs_is_there_with_jazzys_tfmessage():
    """compat/tf2_msgs (built only without a ROS tf2_msgs) defines TFMessage as Jazzy."""
    from rosbags.typesys import Stores, get_typestore
    from tf2_msgs.msg import TFMessage
    assert TFMessage.get_fields_and_field_types() == {
        'transforms': 'sequence<geometry_msgs/TransformStamped>'}
    jazzy, _ = get_typestore(Stores.ROS2_JAZZY).generate_msgdef('tf2_msgs/msg/TFMessage',
                                                               ros_version=2)
    compat = (WORKSPACE / 'compat/tf2_msgs/msg/TFMessage.msg').read_text()
    assert jazzy.split('\n')[0] == compat.strip()
    assert (WORKSPACE / 'compat/COLCON_IGNORE').is_file()
